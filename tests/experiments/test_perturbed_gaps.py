"""``experiments.perturbed_gaps``: the perturbations and the table, on tiny synthetic scenes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from experiments import perturbed_gaps as ex
from pftrack.io.mot import read_mot
from pftrack.recovery.experiment import (
    SequenceResult,
    auto_masks,
    run_mask,
    run_sequence,
    trajectories,
)
from pftrack.synthetic import make_scene
from tests.conftest import dataset


@pytest.fixture(scope="module")
def rows() -> np.ndarray:
    return make_scene(n_frames=60, n_walkers=4, rng=2).truth


def test_pan_moves_every_box_of_a_frame_alike_and_draws_nothing(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "pan", seed=0)
    b = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "pan", seed=5)
    np.testing.assert_array_equal(a, b)
    shift = a[:, 2:4] - rows[:, 2:4]
    for f in np.unique(rows[:, 0]):
        s = shift[rows[:, 0] == f]
        np.testing.assert_allclose(s, np.broadcast_to(s[0], s.shape), atol=1e-9)
    assert np.abs(shift[:, 0]).max() > 0.05 * 480  # a pan of up to 8 % of the width
    np.testing.assert_array_equal(a[:, 4:], rows[:, 4:])  # sizes, ids, frames as they were


def test_shake_is_seeded_and_per_frame(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "shake", seed=1)
    np.testing.assert_array_equal(a, ex.perturbed("s", rows, 480.0, 360.0, 10.0, "shake", seed=1))
    assert not np.array_equal(a, ex.perturbed("s", rows, 480.0, 360.0, 10.0, "shake", seed=2))
    assert not np.array_equal(a, ex.perturbed("t", rows, 480.0, 360.0, 10.0, "shake", seed=1))
    shift = a[:, 2:4] - rows[:, 2:4]
    first = rows[:, 0] == rows[0, 0]
    np.testing.assert_allclose(shift[first], np.broadcast_to(shift[first][0], shift[first].shape))


def test_half_fps_keeps_odd_frames_renumbered(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "halffps", seed=0)
    odd = rows[rows[:, 0] % 2 == 1]
    np.testing.assert_array_equal(a[:, 1:], odd[:, 1:])
    np.testing.assert_array_equal(a[:, 0], (odd[:, 0] + 1) // 2)
    assert a[:, 0].min() == 1


def test_jitter_scales_with_box_height(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "jitter", seed=0)
    d = (a[:, 2:4] - rows[:, 2:4]) / rows[:, 5:6]
    assert 0.015 < float(np.std(d)) < 0.025  # N(0, (0.02 h)^2) per axis
    np.testing.assert_array_equal(a[:, 4:], rows[:, 4:])


def test_table_marks_auto_worse_than_linear_and_pools_by_gaps(rows: np.ndarray) -> None:
    res = {
        how: [
            run_sequence(
                f"tiny-{how}",
                trajectories(ex.perturbed("tiny", rows, 480.0, 360.0, 10.0, how, 0)),
                480.0,
                360.0,
                ("auto", "linear", "rts"),
            )
        ]
        for how in ("pan", "halffps")
    }
    text = ex.format_table(res)
    for how, (r,) in res.items():
        assert r.n_gaps > 0
        line = next(ln for ln in text.splitlines() if ln.startswith(f"tiny-{how} "))
        assert f"{r.mmae('auto'):.3f}" in line and f"{r.mmae('linear'):.3f}" in line
        assert ("<" in line) == (r.mmae("auto") > r.mmae("linear"))
        pooled = next(ln for ln in text.splitlines() if ln.startswith(f"pooled {how} "))
        assert f"{r.mmae('auto'):.3f}" in pooled  # one sequence: its own figures
    worse = [r.name for rs in res.values() for r in rs if r.mmae("auto") > r.mmae("linear")]
    assert text.splitlines()[-1] == f"worse than linear: {', '.join(worse) or 'none'}"


def test_help_shows_the_seed_default(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--help"])
    assert e.value.code == 0
    assert "seed of shake and jitter (default: 0)" in " ".join(capsys.readouterr().out.split())


def test_negative_seed_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--seed", "-1"])
    assert e.value.code == 2
    assert "--seed is -1, expected >= 0" in capsys.readouterr().err


def test_third_fps_keeps_every_third_frame_renumbered(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "thirdfps", seed=0)
    kept = rows[np.isin(rows[:, 0], np.arange(1, rows[:, 0].max() + 1, 3))]  # 1, 4, 7, ...
    np.testing.assert_array_equal(a[:, 1:], kept[:, 1:])
    np.testing.assert_array_equal(a[:, 0], (kept[:, 0] - 1) / 3 + 1)
    assert a[:, 0].min() == 1
    assert np.array_equal(np.unique(a[:, 0]), np.arange(1, a[:, 0].max() + 1))  # no frame lost


def test_zoom_scales_boxes_about_the_image_centre_and_draws_nothing(rows: np.ndarray) -> None:
    fps = 10.0
    a = ex.perturbed("s", rows, 480.0, 360.0, fps, "zoom", seed=0)
    np.testing.assert_array_equal(a, ex.perturbed("t", rows, 480.0, 360.0, fps, "zoom", seed=7))
    s = 1.0 + 0.15 * np.sin(2 * np.pi * rows[:, 0] / fps / 10.0)
    np.testing.assert_allclose(a[:, 4:6], rows[:, 4:6] * s[:, None])  # width and height alike
    centre = np.array([240.0, 180.0])
    for col in (0.0, 1.0):  # the corner and the opposite corner both scale about the centre
        got = a[:, 2:4] + col * a[:, 4:6] - centre
        want = (rows[:, 2:4] + col * rows[:, 4:6] - centre) * s[:, None]
        np.testing.assert_allclose(got, want, atol=1e-9)
    assert 1.14 < s.max() < 1.151  # 60 frames at 10 fps: a quarter period is 2.5 s
    np.testing.assert_array_equal(a[:, :2], rows[:, :2])  # frames and ids as they were


def test_fps14_keeps_frames_at_14_of_30_renumbered(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "fps14", seed=0)
    np.testing.assert_array_equal(a, ex.perturbed("t", rows, 480.0, 360.0, 25.0, "fps14", seed=3))
    last = int(rows[:, 0].max())
    old = [1 + round(k * 30 / 14) for k in range(last) if 1 + round(k * 30 / 14) <= last]
    assert old[:6] == [1, 3, 5, 7, 10, 12]  # steps of 2 or 3 old frames, unevenly
    assert set(np.diff(old)) == {2, 3}
    for new, f in enumerate(old, start=1):
        np.testing.assert_array_equal(a[a[:, 0] == new, 1:], rows[rows[:, 0] == f, 1:])
    assert len(a) == int(np.isin(rows[:, 0], old).sum())  # the other frames are dropped
    assert np.array_equal(np.unique(a[:, 0]), np.arange(1, len(old) + 1))


def test_walk_scales_about_the_centre_from_1_to_1_5_over_the_file(rows: np.ndarray) -> None:
    a = ex.perturbed("s", rows, 480.0, 360.0, 10.0, "walk", seed=0)
    np.testing.assert_array_equal(a, ex.perturbed("t", rows, 480.0, 360.0, 30.0, "walk", seed=4))
    f0, f1 = rows[:, 0].min(), rows[:, 0].max()
    s = 1.0 + 0.5 * (rows[:, 0] - f0) / (f1 - f0)
    np.testing.assert_allclose(a[:, 4:6], rows[:, 4:6] * s[:, None])
    centre = np.array([240.0, 180.0])
    for col in (0.0, 1.0):
        got = a[:, 2:4] + col * a[:, 4:6] - centre
        want = (rows[:, 2:4] + col * rows[:, 4:6] - centre) * s[:, None]
        np.testing.assert_allclose(got, want, atol=1e-9)
    np.testing.assert_array_equal(a[rows[:, 0] == f0], rows[rows[:, 0] == f0])  # 1 at the start
    np.testing.assert_allclose(a[rows[:, 0] == f1, 4:6], 1.5 * rows[rows[:, 0] == f1, 4:6])
    np.testing.assert_array_equal(a[:, :2], rows[:, :2])


def _result(name: str, auto: float) -> SequenceResult:
    errors = {"auto": (auto, auto), "linear": (1.2, 1.2), "rts": (1.0, 1.0)}
    return SequenceResult(name, (480.0, 360.0), (), 2, errors)


def test_table_lists_copies_more_than_2_percent_above_the_best_fixed() -> None:
    text = ex.format_table({"zoom": [_result("a-zoom", 1.03), _result("b-zoom", 1.01)]})
    lines = text.splitlines()
    assert lines[-2] == "more than 2 % above the best fixed: a-zoom"  # 1.01 is within 2 % of rts
    assert lines[-1] == "worse than linear: none"
    text = ex.format_table({"zoom": [_result("b-zoom", 1.01)]})
    assert text.splitlines()[-2] == "more than 2 % above the best fixed: none"


def test_only_runs_the_perturbations_named(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    ran: list[tuple[str, ...]] = []

    def score(root: Path, seed: int, only: tuple[str, ...]) -> dict[str, list[SequenceResult]]:
        ran.append(only)
        return {how: [_result(f"s-{how}", 1.0)] for how in only}

    monkeypatch.setattr(ex, "score", score)
    assert ex.main(["--only", "zoom, thirdfps", "--out", str(tmp_path)]) == 0
    assert ran == [("zoom", "thirdfps")]
    text = (tmp_path / "perturbed_seed0.txt").read_text()
    assert "pooled zoom " in text and "pooled thirdfps " in text and "pooled pan " not in text


@pytest.mark.parametrize("only", ["foo", "zoom,foo", ","])
def test_unknown_perturbation_is_refused(only: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--only", only])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"--only is {only!r}, expected a comma-separated list of pan, shake" in err


@pytest.mark.xfail(
    strict=True, reason="gaps of 5-8 frames at a clipped image edge, validated in the interior"
)
def test_auto_is_not_worse_than_linear_on_syn0_thirdfps_at_the_right_edge() -> None:
    # syn0 of experiments.auto_seeds at a third of its frame rate, its second automatic mask:
    # 6 of its 8 gaps lie 14-18 px from the right edge, where make_scene clips the boxes (their
    # centres then move as no interior run does); auto 2.473 px a gap, linear 2.080.
    scene = make_scene(n_frames=300, n_walkers=12, rng=0)
    trajs = trajectories(ex.perturbed("syn0", scene.truth, 480.0, 360.0, scene.fps, "thirdfps", 0))
    mask = (406.0, 158.0, 62.0, 62.0)
    assert mask in auto_masks(trajs, 480.0, 360.0, 3)
    run = run_mask(trajs, mask, ("auto", "linear"), seed=0)
    assert len(run.gaps) == 8
    err = {
        m: np.mean([np.mean(g.errors(p)) for g, p in zip(run.gaps, run.paths[m], strict=True)])
        for m in run.paths
    }
    assert err["auto"] <= err["linear"], err


@pytest.mark.xfail(
    strict=True,
    raises=AssertionError,
    reason="gaps of 5-8 frames validated on 7 artificial gaps of few short runs",
)
def test_auto_is_not_worse_than_linear_on_tud_campus_fps14() -> None:
    # TUD-Campus resampled as a 30 fps file seen at 14 fps (fps14), its first mask: the
    # bucket of 5-8 frames (4 real gaps) has 7 validation gaps, all at random places of short
    # runs; they rate gdt-bi 3.73 px against linear 4.09, the real gaps 21.05 px summed
    # against 19.78 (docs/recovery.md, stop 68).
    gt = read_mot(dataset("tud-campus") / "gt.txt")
    trajs = trajectories(ex.perturbed("TUD-Campus", gt, 640.0, 480.0, 25.0, "fps14", 0))
    mask = auto_masks(trajs, 640.0, 480.0, 3)[0]
    run = run_mask(trajs, mask, ("auto", "linear"), seed=0)
    if mask[:2] != (243.0, 276.0) or len(run.gaps) != 7:  # not the case described: a failure
        pytest.fail(f"mask {mask}, {len(run.gaps)} gaps: expected 243, 276 and 7 gaps")
    err = {
        m: sum(float(np.mean(g.errors(p))) for g, p in zip(run.gaps, run.paths[m], strict=True))
        for m in run.paths
    }
    assert err["auto"] <= err["linear"], err
