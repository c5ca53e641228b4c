"""The crowd video of issue 17's goal: seeded, its count in view, its truth, its files."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from experiments import crowd_video as exp
from pftrack.io.mot import read_mot


def test_crowd_is_seeded_and_keeps_its_count_in_view():
    def run(seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
        return list(exp.crowd_frames(20, 40, (320, 180), seed=seed))

    a, b, other = run(3), run(3), run(4)
    assert all(np.array_equal(fa, fb) and np.array_equal(ta, tb)
               for (fa, ta), (fb, tb) in zip(a, b, strict=True))  # fmt: skip
    assert not np.array_equal(a[0][0], other[0][0])
    truth = np.concatenate([t for _, t in a])
    for f, (frame, rows) in enumerate(a, start=1):
        assert frame.shape == (180, 320, 3) and frame.dtype == np.uint8
        assert np.all(rows[:, 0] == f)
        assert 15 <= len(rows) <= 20  # a leaver is replaced at once; one at a border may not show
        assert len(np.unique(rows[:, 1])) == len(rows)
        x, y, w, h = rows[:, 2:6].T
        assert np.all((x >= 0) & (y >= 0) & (w > 0) & (h > 0))
        assert np.all((x + w <= 320) & (y + h <= 180))
    assert truth[:, 1].max() > 20  # people left and others came in
    ids = truth[:, 1]
    first, last = (truth[ids == ids[0]][k, 2] for k in (0, -1))
    assert first != last  # they walk
    with pytest.raises(ValueError, match="n_walkers"):
        next(exp.crowd_frames(0, 5))


def test_main_writes_an_mjpg_video_and_its_truth(tmp_path: Path):
    exp.main(["--out", str(tmp_path), "--walkers", "5", "--frames", "6", "--seed", "1"])
    cap = cv2.VideoCapture(str(tmp_path / "crowd.avi"))
    fourcc = int(cap.get(cv2.CAP_PROP_FOURCC)).to_bytes(4, "little").decode()
    n = 0
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        assert frame.shape == (720, 1280, 3)
        n += 1
    assert fourcc == "MJPG" and n == 6
    gt = read_mot(tmp_path / "gt.txt")
    assert set(gt[:, 0].astype(int)) == set(range(1, 7))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.avi", "gt.txt"]  # no temp left
    with pytest.raises(SystemExit):
        exp.main(["--out", str(tmp_path), "--walkers", "0"])
