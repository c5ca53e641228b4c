"""Writing a MOTChallenge file: the C++ text kernel against the ``%`` formatting it replaced.

``mot text, 500 tracks``: the lines of :mod:`bench.recovery_file`'s 500-track file (61 981 rows,
as ``pftrack recover`` writes them) by ``pftrack.io.mot._lines`` (``_printable``'s NumPy, then
``_core.mot_lines``) and by ``tests/reference/text.py`` (the same ``_printable``, then one Python
``%`` over every value), the same text. The ratio of the medians is in
``extra_info["x_python"]`` of the second; it must be at least :data:`FLOOR`.

``mot read, 500 tracks``: the same file's text (as :func:`pftrack.io.mot.write_mot` writes it,
3.6 MB) read back by ``_core.parse_mot_text`` (the bytes read, then one C++ pass: what
``read_mot``'s fast path calls first) and by ``np.loadtxt`` as ``read_mot`` called it before
(``pftrack.io.mot._loadtxt``), the same doubles; the ratio of the medians is in
``extra_info["x_loadtxt"]``, at least :data:`READ_FLOOR`.

Locally: ``pytest bench/test_io.py --benchmark-enable --benchmark-only``; CI:
``--benchmark-disable``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from bench.recovery_file import synthetic_tracks
from pftrack import _core
from pftrack._typing import F64
from pftrack.io.mot import _checked, _lines, _loadtxt
from tests.reference import text as ref_text

#: Least speed-up of ``_lines`` over the ``%`` reference in the same run (measured 5.4x on a
#: quiet machine, 27 against 145 ms with ``_printable``'s 20 ms in both; 2.8x while another
#: job shared the cores): below what is measured, so that only a regression fails.
FLOOR = 2.0
_MEDIANS: dict[str, float] = {}
#: Least speed-up of ``parse_mot_text`` over ``np.loadtxt`` in the same run (measured 12.5x,
#: medians 7.6 against 95 ms, while other jobs shared the 2 cores): only a regression fails.
READ_FLOOR = 4.0
_READ_MEDIANS: dict[str, float] = {}


def _check_ratio(
    benchmark: BenchmarkFixture,
    medians: dict[str, float],
    how: str,
    slow: str,
    floor: float,
    what: str,
) -> None:
    """Keep this run's median; once both sides ran, `slow`'s over ``core``'s must reach `floor`.

    The ratio goes to ``extra_info["x_<slow>"]`` of the second. Nothing under
    ``--benchmark-disable`` (no timing).
    """
    if not benchmark.stats:
        return
    medians[how] = benchmark.stats.stats.median
    if len(medians) == 2:
        ratio = medians[slow] / medians["core"]
        benchmark.extra_info[f"x_{slow}"] = round(ratio, 1)
        assert ratio >= floor, f"{what}: {ratio:.1f}x, below {floor}x"


@pytest.fixture(scope="module")
def rows_500() -> F64:
    return _checked(synthetic_tracks(500, seed=0), "bench")


@pytest.mark.parametrize("how", ["core", "python"])
def test_mot_text(benchmark: BenchmarkFixture, rows_500: F64, how: str) -> None:
    benchmark.group = "mot text, 500 tracks"
    run = _lines if how == "core" else ref_text.lines
    text = benchmark.pedantic(run, args=(rows_500,), rounds=5, iterations=1)
    assert text == (ref_text.lines(rows_500) if how == "core" else _lines(rows_500))
    _check_ratio(benchmark, _MEDIANS, how, "python", FLOOR, "_lines against the % reference")


@pytest.fixture(scope="module")
def file_500(rows_500: F64, tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("mot") / "t500.txt"
    path.write_text(_lines(rows_500))
    return path


def _parse(path: Path) -> F64 | None:
    return _core.parse_mot_text(path.read_bytes())


@pytest.mark.parametrize("how", ["core", "loadtxt"])
def test_mot_read(benchmark: BenchmarkFixture, file_500: Path, how: str) -> None:
    benchmark.group = "mot read, 500 tracks"
    run = _parse if how == "core" else lambda path: _loadtxt(path, "utf-8-sig")
    got = benchmark.pedantic(run, args=(file_500,), rounds=5, iterations=1)
    other = _loadtxt(file_500, "utf-8-sig") if how == "core" else _parse(file_500)
    assert got is not None and other is not None and got.shape == other.shape
    assert np.array_equal(got.view(np.int64), other.view(np.int64))  # bit for bit
    _check_ratio(
        benchmark, _READ_MEDIANS, how, "loadtxt", READ_FLOOR, "parse_mot_text against loadtxt"
    )
