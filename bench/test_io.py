"""Writing a MOTChallenge file: the C++ text kernel against the ``%`` formatting it replaced.

``mot text, 500 tracks``: the lines of :mod:`bench.recovery_file`'s 500-track file (61 981 rows,
as ``pftrack recover`` writes them) by ``pftrack.io.mot._lines`` (``_printable``'s NumPy, then
``_core.mot_lines``) and by ``tests/reference/text.py`` (the same ``_printable``, then one Python
``%`` over every value), the same text. The ratio of the medians is in
``extra_info["x_python"]`` of the second; it must be at least :data:`FLOOR`.

Locally: ``pytest bench/test_io.py --benchmark-enable --benchmark-only``; CI:
``--benchmark-disable``.
"""

from __future__ import annotations

import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from bench.recovery_file import synthetic_tracks
from pftrack._typing import F64
from pftrack.io.mot import _checked, _lines
from tests.reference import text as ref_text

#: Least speed-up of ``_lines`` over the ``%`` reference in the same run (measured 5.4x on a
#: quiet machine, 27 against 145 ms with ``_printable``'s 20 ms in both; 2.8x while another
#: job shared the cores): below what is measured, so that only a regression fails.
FLOOR = 2.0
_MEDIANS: dict[str, float] = {}


@pytest.fixture(scope="module")
def rows_500() -> F64:
    return _checked(synthetic_tracks(500, seed=0), "bench")


@pytest.mark.parametrize("how", ["core", "python"])
def test_mot_text(benchmark: BenchmarkFixture, rows_500: F64, how: str) -> None:
    benchmark.group = "mot text, 500 tracks"
    run = _lines if how == "core" else ref_text.lines
    text = benchmark.pedantic(run, args=(rows_500,), rounds=5, iterations=1)
    assert text == (ref_text.lines(rows_500) if how == "core" else _lines(rows_500))
    if not benchmark.stats:  # --benchmark-disable: no timing
        return
    _MEDIANS[how] = benchmark.stats.stats.median
    if len(_MEDIANS) == 2:
        ratio = _MEDIANS["python"] / _MEDIANS["core"]
        benchmark.extra_info["x_python"] = round(ratio, 1)
        assert ratio >= FLOOR, f"_lines is {ratio:.1f}x the % reference, below {FLOOR}x"
