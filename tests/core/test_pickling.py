"""Every class of the compiled core pickles, or refuses with TypeError, at every protocol.

pybind11's ``py::pickle`` serves protocol 2 and up only: below that (and for a class with no
pickling at all) Python's copyreg fallback makes pybind11 abort the interpreter (SIGABRT,
"instance allocation failed: new instance has no pybind11-registered base types"). Each check
runs in a child process, so that an abort fails the test instead of ending pytest.
"""

from __future__ import annotations

import inspect
import pickle
import subprocess
import sys

import pytest

from pftrack import _core

#: The classes of pftrack._core and what pickle does with them: a new class must be added here
#: (and given a __reduce__: cpp/bindings/pickling.hpp).
PICKLING = {
    "BackgroundModel": """
m = _core.BackgroundModel(alpha=0.07, n_learn=4)
rng = np.random.default_rng(5)
frames = [rng.integers(0, 256, (24, 32, 3), dtype=np.uint8) for _ in range(8)]
for f in frames[:5]:
    m.apply(f)
c = pickle.loads(pickle.dumps(m, protocol=protocol))
assert type(c) is _core.BackgroundModel and c.__getstate__() == m.__getstate__()
for f in frames[5:]:
    assert m.apply(f)[1].tobytes() == c.apply(f)[1].tobytes()
fresh = pickle.loads(pickle.dumps(_core.BackgroundModel(), protocol=protocol))
assert fresh.shape is None
""",
    "BinnedImage": """
b = _core.BinnedImage(np.array([[0, 1], [-1, 4]], np.int16), 5)
c = pickle.loads(pickle.dumps(b, protocol=protocol))
assert c.n_bins == 5 and c.bins.tolist() == b.bins.tolist()
""",
    "RJMCMCTracker": """
try:
    pickle.dumps(_core.RJMCMCTracker(), protocol=protocol)
except TypeError as e:
    assert str(e).startswith("cannot pickle 'pftrack._core.RJMCMCTracker' object: "), e
else:
    raise AssertionError("pickled")
""",
}


def test_every_core_class_is_listed():
    classes = [n for n, c in inspect.getmembers(_core, inspect.isclass)
               if not issubclass(c, BaseException)]  # fmt: skip
    assert sorted(classes) == sorted(PICKLING)


@pytest.mark.parametrize("name", sorted(PICKLING))
def test_a_core_class_at_every_protocol(name: str) -> None:
    code = "\n".join([
        "import pickle", "import numpy as np", "from pftrack import _core",
        f"for protocol in range({pickle.HIGHEST_PROTOCOL + 1}):",
        *("    " + line for line in PICKLING[name].strip().splitlines()),
        "    print(protocol, flush=True)",
    ])  # fmt: skip
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == [str(p) for p in range(pickle.HIGHEST_PROTOCOL + 1)]
