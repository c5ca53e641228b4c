"""``experiments.public_detections``: black frames, noisy detections, one scene end to end."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from experiments import public_detections as ex
from pftrack._typing import F64
from pftrack.eval import evaluate_sequence
from pftrack.synthetic import Scene, make_busy_scene
from pftrack.tracking import TrackerConfig, track_frames


def test_black_frames_share_one_read_only_array() -> None:
    frames = ex.BlackFrames(3, 8, 6)
    assert len(frames) == 3 and frames[0].shape == (6, 8, 3) and not frames[0].any()
    assert frames[0] is frames[-1] and not frames[0].flags.writeable
    assert len(list(frames)) == 3
    with pytest.raises(IndexError):
        frames[3]


def test_noisy_detections_are_seeded_and_close_to_the_truth() -> None:
    scene = make_busy_scene("groups", n_frames=60, rng=0)
    a = ex.noisy_detections(scene.truth, 60, 360, 480, seed=1)
    b = ex.noisy_detections(scene.truth, 60, 360, 480, seed=1)
    assert a.keys() == b.keys() and all(np.array_equal(a[f], b[f]) for f in a)
    n_truth = len(scene.truth)
    n_det = sum(len(d) for d in a.values())
    assert 0.8 * n_truth < n_det < 1.2 * n_truth  # 10 % missed, a false box every other frame
    run = track_frames(scene.frames, detections=a, config=TrackerConfig(), rng=0)
    s = evaluate_sequence(scene.truth, run.rows)
    assert s.mot.mota > 0.3 and s.hota.hota > 0.3  # the tracker follows the jittered boxes


def test_override_changes_one_field_and_refuses_unknown_ones() -> None:
    base = TrackerConfig()
    c = ex.override(base, "motion.colour_noise=0.2")
    assert c.motion.colour_noise == 0.2 and c.motion.accel == base.motion.accel
    assert c.association == base.association and base.motion.colour_noise != 0.2
    assert ex.override(base, "reference_rate=0").reference_rate == 0.0
    assert ex.override(base, "lifecycle.birth_quantile=none").lifecycle.birth_quantile is None
    assert ex.override(base, "lifecycle.max_coast=4").lifecycle.max_coast == 4
    assert ex.override(base, "motion.smooth_external=false").motion.smooth_external is False
    for bad in ("motion.colour_noise", "motion.nope=1", "nope.accel=1", "a.b.c=1",
                "lifecycle.max_coast=x", "filter=3"):  # fmt: skip
        with pytest.raises(ValueError, match="--set"):
            ex.override(base, bad)
    with pytest.raises(ValueError, match="max_coast"):  # the config's own check still runs
        ex.override(base, "lifecycle.max_coast=-1")


@pytest.mark.parametrize(
    ("setting", "message"),
    [  # were: "'x' is not a NoneType", "is not a int", "'lifecycle' is not a number, ..."
        ("max_side=x", "'x' is not a number (or none)"),  # a field None by default
        ("lifecycle.size_ratio=x", "'x' is not a number"),
        ("hold_frames=1.5", "'1.5' is not an int"),
        ("reference_rate=x", "'x' is not a number"),
        ("lifecycle=1", "'lifecycle' is a section: give lifecycle.FIELD=VALUE"),
    ],
)
def test_a_bad_setting_says_what_the_field_takes(setting: str, message: str) -> None:
    with pytest.raises(
        ValueError, match=f"^--set {re.escape(repr(setting))}: {re.escape(message)}$"
    ):
        ex.override(TrackerConfig(), setting)


def test_main_rejects_a_bad_setting(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--set", "motion.nope=1"])
    assert e.value.code == 2 and "no field 'motion.nope'" in capsys.readouterr().err


def test_resized_frames_and_scaled_detections() -> None:
    frames = [np.full((6, 8, 3), i, np.uint8) for i in range(3)]
    big = ex.Resized(frames, 2.0)
    assert len(big) == 3 and big[1].shape == (12, 16, 3) and (big[1] == 1).all()
    assert [f.shape for f in big] == [(12, 16, 3)] * 3
    assert ex.Resized(frames, 1.0)[2] is frames[2]
    dets = {1: np.array([[1.0, 2.0, 3.0, 4.0, 0.5]])}
    assert np.array_equal(ex.scaled(dets, 2.0)[1], [[2.0, 4.0, 6.0, 8.0, 0.5]])
    assert ex.override(TrackerConfig(), "pixel_diagonal=none").pixel_diagonal is None


@pytest.mark.parametrize("factor", ["0", "nan", "100"])
def test_main_rejects_a_bad_upscale(factor: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--upscale", factor])
    assert e.value.code == 2 and "--upscale" in capsys.readouterr().err


def test_override_of_an_unset_field_takes_an_int_or_a_float() -> None:
    assert ex.override(TrackerConfig(), "max_side=640").max_side == 640
    assert ex.override(TrackerConfig(), "pixel_diagonal=400.5").pixel_diagonal == 400.5


def test_late_and_low_drops_the_first_frames_and_squeezes_scores() -> None:
    """``--empty N`` removes frames 1..N; ``--low-scores`` puts scores in [0.2, 0.5], ranked."""
    dets = {f: np.array([[1.0, 2.0, 3.0, 4.0, s] for s in (0.3, 0.6, 1.0)]) for f in (1, 2, 3)}
    assert ex.late_and_low(dets, 0, False) == dets
    out = ex.late_and_low(dets, 2, True)
    assert list(out) == [3]
    assert np.allclose(out[3][:, 4], [0.2, 0.26, 0.5]) and np.array_equal(
        out[3][:, :4], dets[3][:, :4]
    )


@pytest.mark.filterwarnings("ignore:the video is grey:UserWarning")  # overhead is grey
def test_scene_seed_makes_the_scenes_and_their_detections(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``--scene-seed``: the synthetic scenes and their detections use it; 0 is today's."""
    seeds: list[tuple[str, object]] = []

    def scene(kind: str, rng: int) -> Scene:
        seeds.append(("scene", rng))
        return make_busy_scene(kind, n_frames=8, rng=rng)

    def dets(truth: F64, n: int, h: int, w: int, seed: int = 0) -> dict[int, F64]:
        seeds.append(("dets", seed))
        return real_dets(truth, n, h, w, seed)

    real_dets = ex.noisy_detections
    monkeypatch.setattr(ex, "make_busy_scene", scene)
    monkeypatch.setattr(ex, "noisy_detections", dets)
    scores = ex.run_all(tmp_path, TrackerConfig(), 0, scene_seed=12)
    assert len(scores) == 3 and seeds == [("scene", 12), ("dets", 12)] * 3
    seeds.clear()
    ex.run_all(tmp_path, TrackerConfig(), 0)
    assert seeds == [("scene", 0), ("dets", 0)] * 3


def test_main_rejects_a_negative_scene_seed(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--scene-seed", "-1"])
    assert e.value.code == 2 and "--scene-seed is -1, expected a seed >= 0" in (
        capsys.readouterr().err
    )
