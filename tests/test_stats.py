"""pftrack._stats: NumPy's median, percentile and unique values, the same floats, no numpy.ma."""

from __future__ import annotations

import math
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from pftrack._check import refuse_masked
from pftrack._stats import median, median_along, percentile, unique_values
from pftrack.synthetic import make_scene


def _samples(rng: np.random.Generator) -> list[np.ndarray]:
    """Odd and even counts; distinct, tied, integer, float32 and NaN-holding values."""
    out: list[np.ndarray] = []
    for n in (1, 2, 3, 4, 5, 8, 31, 200, 1001):
        out.append(rng.standard_normal(n))
        out.append(rng.integers(0, 4, n).astype(np.float64))  # many ties
        out.append(rng.integers(-300, 300, n).astype(np.int16))
        out.append(rng.integers(0, 256, n).astype(np.uint8))
        out.append(rng.integers(-(2**40), 2**40, n))  # int64: percentile goes to NumPy
        out.append(rng.standard_normal(n).astype(np.float32))
        with_nan = rng.standard_normal(n)
        with_nan[rng.integers(n)] = np.nan
        out.append(with_nan)
    out.append(rng.standard_normal((6, 7)))  # flattened, as NumPy's axis=None
    out.append(np.array([0.0, -0.0, 0.0, -0.0]))
    out.append(np.array([np.inf, -np.inf, 1.0, np.inf]))
    return out


def _same(a: float, b: float) -> bool:
    """Equal, zeros of one sign, or both NaN."""
    both_nan = math.isnan(a) and math.isnan(b)
    return both_nan or (a == b and math.copysign(1, a) == math.copysign(1, b))


def test_median_and_percentile_are_numpys_floats(rng: np.random.Generator) -> None:
    for a in _samples(rng):
        assert _same(median(a), float(np.median(a))), a
        assert _same(median(a.tolist()), float(np.median(a.tolist()))), a
        for q in (0, 0.5, 1, 25, 50, 75, 99, 99.9, 100, *rng.uniform(0, 100, 5)):
            with np.errstate(invalid="ignore"):  # NumPy's inf - inf, in both
                assert _same(percentile(a, q), float(np.percentile(a, q))), (a, q)


def test_median_along_is_numpys(rng: np.random.Generator) -> None:
    for n in (1, 2, 3, 4, 7, 10):
        stack = rng.standard_normal((5, n, 9, 2))
        stack[:, :, 3] = np.round(stack[:, :, 3])  # ties
        np.testing.assert_array_equal(median_along(stack, 1), np.median(stack, axis=1))
        stack[2, 0, 4, 1] = np.nan
        np.testing.assert_array_equal(median_along(stack, 1), np.median(stack, axis=1))
        np.testing.assert_array_equal(median_along(stack, 2), np.median(stack, axis=2))


def test_unique_values_are_numpys(rng: np.random.Generator) -> None:
    for a in _samples(rng):
        np.testing.assert_array_equal(unique_values(a), np.unique(a))


def test_other_input_goes_to_numpy() -> None:
    """Empty, masked or out-of-range input gives NumPy's own answer, warning or error."""
    masked = np.ma.masked_array([1.0, 2.0, 100.0], mask=[False, False, True])
    with pytest.warns(UserWarning, match="ignore the 'mask'"):  # NumPy's own warning
        assert median(masked) == 2.0
    with pytest.warns(RuntimeWarning, match="empty"), np.errstate(invalid="ignore"):
        assert math.isnan(median(np.array([])))
    with pytest.raises(ValueError, match="Percentiles must be in the range"):
        percentile([1.0, 2.0], 101)
    # boolean and complex
    assert median([True, False, True]) == float(np.median([True, False, True]))
    with pytest.raises(IndexError):
        percentile(np.array([], dtype=np.float64), 50)


def test_a_track_run_never_imports_numpy_ma(tmp_path: Path) -> None:
    """The built-in detector's priming, the offline pass and the summary use these, not NumPy's.

    ``numpy.ma`` (15-20 ms of CPU) was imported in every ``pftrack track``'s first second by
    ``np.median`` (``light.frame_gain``), later by ``np.percentile``, ``np.unique``
    (the writer's classes, the summary's count) and the recovery's neighbour medians.
    """
    video = make_scene(n_frames=60, rng=0).write_video(tmp_path / "scene.avi")
    code = (
        "import sys; from pftrack.cli import main; "
        f"status = main(['-q', 'track', {str(video)!r}, '--out', {str(tmp_path / 't.txt')!r}]); "
        "print(status, 'numpy.ma' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split()[-2:] == ["0", "False"], out.stderr
    assert (tmp_path / "t.txt").stat().st_size > 0


def test_the_masked_check_passes_while_another_thread_imports_numpy_ma(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``refuse_masked`` reads ``sys.modules["numpy.ma"]``, which exists without its names
    while another thread imports it (now late in a run: this module's functions no longer
    import it early). Was an AttributeError (``partially initialized module 'numpy.ma' has no
    attribute 'MaskedArray'``) on ``pftrack track --render``'s drawing thread after a Ctrl-C."""
    monkeypatch.setitem(sys.modules, "numpy.ma", types.ModuleType("numpy.ma"))
    refuse_masked(np.zeros((2, 3)), "rows")  # no error: nothing masked can exist yet
    monkeypatch.undo()
    masked = np.ma.masked_array([1.0, 2.0], mask=[True, False])
    with pytest.raises(TypeError, match="rows is a numpy.ma.MaskedArray with 1 masked value"):
        refuse_masked(masked, "rows")


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_recover_and_smooth_never_import_numpy_ma(tmp_path: Path, command: str) -> None:
    """Was: ``np.isin`` in ``recovery.fill.copied_values`` (``pftrack recover``) and
    ``np.unique`` in the summary of ``pftrack smooth`` imported ``numpy.ma`` (15-20 ms of CPU)."""
    from bench.recovery_file import synthetic_tracks
    from pftrack.io.mot import write_mot

    tracks = tmp_path / "t.txt"
    write_mot(tracks, synthetic_tracks(20, seed=1, n_frames=300))
    code = (
        "import sys; from pftrack.cli import main; "
        f"status = main(['-q', {command!r}, {str(tracks)!r}, '--out', "
        f"{str(tmp_path / 'o.txt')!r}]); print(status, 'numpy.ma' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split()[-2:] == ["0", "False"], out.stderr
    assert (tmp_path / "o.txt").stat().st_size > (tmp_path / "t.txt").stat().st_size  # filled
