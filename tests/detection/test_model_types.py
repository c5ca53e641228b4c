"""`PaperDetector.model` (the C++ ``BackgroundModel``) is typed as it returns.

Was: its ``shape`` and ``background`` were ``Any`` in python/pftrack/_core.pyi (pybind11 gives a
property no return type), so a user's ``model.background.mean()`` or ``h, w = model.shape``
was not checked by mypy, before the first frame either, when both are None.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import pftrack
from pftrack.detection.paper import PaperDetector


def test_shape_and_background_are_what_the_stub_says() -> None:
    model = PaperDetector().model
    assert model.shape is None and model.background is None  # before the first frame
    frame = np.random.default_rng(0).integers(0, 256, (6, 8, 3), dtype=np.uint8)
    model.apply(frame)
    shape, background = model.shape, model.background
    assert type(shape) is tuple and shape == (6, 8) and all(type(n) is int for n in shape)
    assert isinstance(background, np.ndarray)
    assert background.dtype == np.float32 and background.shape == (6, 8, 3)
    np.testing.assert_array_equal(background, frame.astype(np.float32))  # the first frame


def test_mypy_sees_the_types(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    api = pytest.importorskip("mypy.api")
    root = Path(pftrack.__file__).parents[1]
    if root.name not in ("site-packages", "dist-packages"):
        monkeypatch.setenv("MYPYPATH", str(root))  # a source checkout (as tests/test_api.py)
    code = tmp_path / "model.py"
    code.write_text(
        "from pftrack.detection.paper import PaperDetector\n"
        "model = PaperDetector().model\n"
        "reveal_type(model.shape)\n"
        "reveal_type(model.background)\n"
        "h, w = model.shape\n"  # None before the first frame: refused
        "model.background.mean()\n"  # refused for the same reason
    )
    out, _, status = api.run(["--strict", "--no-incremental", "--follow-imports=silent", str(code)])
    assert status == 1, out
    shape, background = re.findall(r'Revealed type is "(.*)"', out)
    assert shape.replace("builtins.", "") == "tuple[int, int] | None"  # was: Any
    assert re.fullmatch(r"numpy\.ndarray\[.*numpy\.floating\[.*_32Bit\]\]\] \| None", background)
    assert "model.py:5: error:" in out and "model.py:6: error:" in out, out
