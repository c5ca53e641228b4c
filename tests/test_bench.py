"""The benchmarks' own machinery: their NumPy baselines compute what the core computes, and
their ratios land in ``extra_info`` under the names the docs quote."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from bench import conftest as bench_conftest
from bench import recovery_file
from pftrack import _core
from pftrack.synthetic import make_scene
from tests.reference import fused


@pytest.mark.parametrize("kind", ["noise", "scene"])
def test_hsv_bins_baseline_is_the_cores_bins(kind: str) -> None:
    # cv2.cvtColor's 8-bit S and V put 4 % of PETS09's pixels in another bin: the baseline of
    # bench/test_kernels.py's "hsv bins" groups was another computation until 6 December
    if kind == "noise":
        frame = np.random.default_rng(0).integers(0, 256, (120, 160, 3), dtype=np.uint8)
    else:
        frame = make_scene(n_frames=1, width=160, height=120, rng=0).frames[0]
    np.testing.assert_array_equal(fused.hsv_bins(frame), _core.hsv_bins(frame).bins)


def test_resample_baselines_are_the_cores() -> None:
    w = np.random.default_rng(2).random(1000)
    w /= w.sum()
    u = np.random.default_rng(5).random(1000)
    np.testing.assert_array_equal(
        fused.systematic_resample(w, 0.37), _core.systematic_resample(w, 0.37)
    )
    np.testing.assert_array_equal(fused.stratified_resample(w, u), _core.stratified_resample(w, u))


def _timed(group: str, median: float | None) -> Any:
    stats = None if median is None else SimpleNamespace(stats=SimpleNamespace(median=median))
    return SimpleNamespace(group=group, stats=stats, extra_info={})


def test_ratios_name_each_baseline_on_the_later_benchmark(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(bench_conftest, "_MEDIANS", {})
    core, api = _timed("g", 0.002), _timed("g", 0.004)
    assert bench_conftest.ratios(core, "core") == {}
    assert bench_conftest.ratios(api, "api") == {}
    numpy = _timed("g", 0.02)
    assert bench_conftest.ratios(numpy, "numpy") == {("core", "numpy"): 10.0, ("api", "numpy"): 5.0}
    assert numpy.extra_info == {"x_numpy_core": 10.0, "x_numpy_api": 5.0}
    lattice = _timed("g", 0.001)  # a pftrack role after the baseline: x_<baseline>
    assert bench_conftest.ratios(lattice, "lattice") == {("lattice", "numpy"): 20.0}
    assert lattice.extra_info == {"x_numpy": 20.0}
    other = _timed("other group", 0.5)  # groups never mix
    assert bench_conftest.ratios(other, "stonesoup") == {}
    untimed = _timed("g", None)  # --benchmark-disable: nothing recorded
    assert bench_conftest.ratios(untimed, "filterpy") == {}
    assert untimed.extra_info == {}


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--tracks", "0"], "n_tracks is 0, expected >= 1"),
        (["--seed", "-1"], "expected non-negative"),
    ],
)
def test_recovery_file_bad_arguments_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    with pytest.raises(SystemExit) as exc:
        recovery_file.main([str(tmp_path / "t.txt"), *argv])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert message in err[-1] and "Traceback" not in "\n".join(err)


def test_recovery_file_unwritable_out_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "file").write_text("")
    with pytest.raises(SystemExit) as exc:
        recovery_file.main([str(tmp_path / "file" / "t.txt"), "--tracks", "2"])
    assert exc.value.code == 2
    assert "file" in capsys.readouterr().err.strip().splitlines()[-1]


def test_kernel_floors_can_fail(monkeypatch: pytest.MonkeyPatch) -> None:
    from bench import test_kernels

    monkeypatch.setattr(bench_conftest, "_MEDIANS", {})
    group = "sis_step_batch 15x200, 100x250 boxes, 1920x1080 black"
    test_kernels._compare(_timed(group, 0.010), "every_pixel")
    with pytest.raises(AssertionError, match="lattice is 2.0x every_pixel, below the floor 3x"):
        test_kernels._compare(_timed(group, 0.005), "lattice")
    unchecked = _timed(group, 0.005)  # the random-noise frame: recorded, not asserted
    test_kernels._compare(unchecked, "lattice", check=False)
    assert unchecked.extra_info == {"x_every_pixel": 2.0}
