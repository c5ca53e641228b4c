"""``pftrack experiment gaps`` on ground truth with holes and with repeated rows.

Regressions of the user trial: a trajectory that skips frames (any tracker's output, ground
truth with holes) failed with "operands could not be broadcast together" (the recovered path
covers every frame of the gap, the truth only the frames it has); a repeated (frame, id) failed
with "recover_gap: segment_a frames must increase strictly" instead of naming the lines.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import write_mot
from pftrack.recovery import experiment as E


def _walkers(n_ids: int = 12, n_frames: int = 120, seed: int = 0) -> np.ndarray:
    """Ground truth of walkers crossing a 768x576 image, one row per frame."""
    rng = np.random.default_rng(seed)
    rows = []
    t = np.arange(1, n_frames + 1, dtype=np.float64)
    for tid in range(1, n_ids + 1):
        start = rng.uniform([100, 100], [650, 450])
        v = rng.uniform(-2, 2, 2)
        xy = start + np.outer(t, v) + np.cumsum(rng.normal(0, 0.4, (n_frames, 2)), axis=0)
        xy = np.clip(xy, 20, [740, 550])
        r = np.zeros((n_frames, 10))
        r[:, 0], r[:, 1], r[:, 2:4], r[:, 4:6], r[:, 6], r[:, 7:] = t, tid, xy - 10, 20, 1, -1
        rows.append(r)
    return np.vstack(rows)


def _holed(gt: np.ndarray) -> np.ndarray:
    """Every 5th row left out, as ``awk -F, 'NR%5!=0'`` does: holes inside every track."""
    return gt[np.arange(len(gt)) % 5 != 4]


def test_gaps_of_a_trajectory_with_holes_are_scored_where_the_truth_has_points() -> None:
    gt = _holed(_walkers())
    trajs = E.trajectories(gt)
    masks = E.auto_masks(trajs, 768, 576)
    run = E.run_mask(trajs, masks[0], ["linear", "rts", "auto"])
    assert run.gaps
    holed = [g for g in run.gaps if len(g.truth) < g.segment_b[0, 0] - g.segment_a[-1, 0] - 1]
    assert holed  # some gap skips frames: its path is longer than its truth
    for g, p in zip(run.gaps, run.paths["linear"], strict=True):
        assert len(p) == g.segment_b[0, 0] - g.segment_a[-1, 0] - 1
        at = g.at_truth(p)
        assert at.shape == (len(g.truth), 2)
        # the straight line between the segments' ends, at the truth's frames
        f0, f1 = g.segment_a[-1, 0], g.segment_b[0, 0]
        s = (g.truth[:, 0] - f0) / (f1 - f0)
        want = (1 - s)[:, None] * g.segment_a[-1, 1:3] + s[:, None] * g.segment_b[0, 1:3]
        np.testing.assert_allclose(at, want, atol=1e-9)
        np.testing.assert_allclose(g.errors(p), np.hypot(*(want - g.truth[:, 1:3]).T))
    pairs = zip(run.gaps, run.paths["linear"], strict=True)
    linear = np.mean([g.errors(p).mean() for g, p in pairs])
    assert run.scores["linear"].mmae_total == pytest.approx(linear)
    res = E.run_sequence("holed", trajs, 768, 576, ["linear", "gdt-mix"])
    assert res.n_gaps > 0 and np.isfinite(res.mmae("gdt-mix"))


def test_trajectories_without_holes_score_as_before() -> None:
    """The full truth: every gap frame has a point, at_truth is the whole path."""
    trajs = E.trajectories(_walkers())
    run = E.run_mask(trajs, E.auto_masks(trajs, 768, 576)[0], ["linear"])
    for g, p in zip(run.gaps, run.paths["linear"], strict=True):
        assert np.array_equal(g.at_truth(p), p)


@pytest.mark.parametrize("multi", [False, True])
def test_cli_runs_on_ground_truth_with_holes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], multi: bool
) -> None:
    gt = tmp_path / "base.txt"
    write_mot(gt, _holed(_walkers()))
    argv = ["experiment", "gaps", "--gt", str(gt), "--image-size", "768x576", "--methods",
            "linear,auto"]  # fmt: skip
    argv += ["--auto-masks"] if multi else ["--max-positions", "3", "--repeat", "1"]
    assert main(argv) == 0, capsys.readouterr().err
    assert "MMAE" in capsys.readouterr().out


def test_repeated_rows_are_named_by_file_and_line_as_recover_names_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    gt = tmp_path / "gt.txt"
    write_mot(gt, _walkers(n_ids=3, n_frames=30))
    lines = gt.read_text().splitlines()
    gt.write_text("\n".join([*lines, lines[4]]) + "\n")  # line 91 repeats line 5
    errors = []
    for argv in (
        ["experiment", "gaps", "--gt", str(gt), "--image-size", "768x576"],
        ["experiment", "gaps", "--gt", str(gt), "--auto-masks", "--image-size", "768x576"],
        ["recover", str(gt), "--out", str(tmp_path / "out.txt")],
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        errors.append(err.split(": error: ", 1)[1])
    assert errors[0] == errors[1] == errors[2]
    assert errors[0].startswith(f"{gt}:91: duplicate rows for frame 2, id 2 (lines 5 and 91)")
    with pytest.raises(ValueError, match="duplicate rows for frame 5, id 1"):
        E.trajectories(np.vstack([_walkers(3, 30), _walkers(3, 30)[4:5]]))
