"""The moving-camera experiment (``python -m experiments.moving_camera``) on a tiny sequence."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from experiments import moving_camera as mc
from experiments._common import REPO
from pftrack.io.mot import read_mot
from pftrack.io.video import read_frames


def test_versions_move_frames_and_boxes_together(data: Path, tmp_path: Path) -> None:
    seq = mc.Source("tiny", "img", 1.0)
    static = mc.make_version(seq, data, tmp_path, "static")
    moving = mc.make_version(seq, data, tmp_path, "moving")
    for folder in (static, moving):
        frames = read_frames(folder / "img1")
        assert len(frames) == 12 and frames[0].shape == (360, 480, 3)
        gt, det = read_mot(folder / "gt.txt"), read_mot(folder / "det.txt")
        np.testing.assert_allclose(gt[:, 2:6], det[:, 2:6])  # one warp for both files
        assert np.all(gt[:, 2:4] >= 0) and np.all(gt[:, 2] + gt[:, 4] <= 480)
    # the static version is the source zoomed by 1.35 about the centre (whole boxes only)
    src = read_mot(data / "tiny" / "gt.txt")
    g_static = read_mot(static / "gt.txt")
    c = np.array([240.0, 180.0])
    for row in g_static[(g_static[:, 4] > 20) & (g_static[:, 2] > 1) & (g_static[:, 2] < 400)]:
        orig = src[(src[:, 0] == row[0]) & (src[:, 1] == row[1])][0]
        want = c + 1.35 * (orig[2:4] + orig[4:6] / 2 - c)
        np.testing.assert_allclose(row[2:4] + row[4:6] / 2, want, atol=1e-6)
    # the moving version is not a fixed offset of it
    g_moving = read_mot(moving / "gt.txt")
    shift = [
        g_moving[(g_moving[:, 0] == f) & (g_moving[:, 1] == 1), 2:4]
        - g_static[(g_static[:, 0] == f) & (g_static[:, 1] == 1), 2:4]
        for f in (1, 12)
    ]
    assert not np.allclose(shift[0], shift[1], atol=1.0)


def test_refuses_an_output_inside_the_repository(data: Path) -> None:
    assert mc.main(["--data", str(data), "--out", str(REPO / "out" / "x")]) == 2
