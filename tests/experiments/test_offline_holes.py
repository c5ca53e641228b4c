"""``experiments.offline_holes``: the holes' ends are sorted by the truth they match, and the
pftrack rows are the drop-in tracker's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from experiments import offline_holes as ex


def _rows(track: int, frames: list[int], left: float) -> list[list[float]]:
    return [[f, track, left, 10.0, 20.0, 40.0, 1, -1, -1, -1] for f in frames]


def test_holes_are_sorted_by_what_their_ends_match() -> None:
    # truth: object 1 at x=0 on frames 1-20, object 2 at x=100 on frames 1-20
    gt = np.array(_rows(1, list(range(1, 21)), 0.0) + _rows(2, list(range(1, 21)), 100.0))
    rows = np.array(
        _rows(7, [1, 2, 5], 0.0)  # a hole of 2 frames on object 1: same
        + _rows(8, [1], 0.0)
        + _rows(8, [4], 100.0)  # 2 frames from object 1 to object 2: other
        + _rows(9, [1], 0.0)
        + _rows(9, [5], 300.0)  # 3 frames from object 1 to nothing: one
        + _rows(10, [1], 300.0)
        + _rows(10, [6], 300.0)  # 4 frames between boxes on nothing: neither
        + _rows(11, [1], 0.0)
        + _rows(11, [12], 0.0)  # 10 frames: longer than max_gap, not filled
    )
    counts = ex.hole_ends(rows, gt, scale=1.0, max_gap=9)
    assert counts == {"same": 2, "other": 2, "one": 3, "neither": 4}
    # the truth's scale is applied (PETS09's truth is in 768x576 pixels)
    assert ex.hole_ends(rows[:3], gt * [1, 1, 2, 2, 2, 2, 1, 1, 1, 1], scale=0.5) == {"same": 2}


def test_the_pftrack_row_is_the_drop_in_trackers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kitti17: tuple[Path, tuple[float, float]]
) -> None:
    data_dir, (mota, idf1) = kitti17
    code = ex.main(["--data", str(data_dir), "--seq", "KITTI-17", "--out", str(tmp_path)])
    assert code == 0
    row = next(
        r for r in capsys.readouterr().out.splitlines() if r.startswith("| KITTI-17 | pftrack")
    )
    cells = [c.strip() for c in row.split("|")[3:-1]]
    assert len(cells) == len(ex.STEPS)
    assert cells[-1].startswith(f"{mota} / {idf1} (")  # finalize: what pftrack track writes
    assert (tmp_path / "offline_holes.md").read_text().count("| KITTI-17 | pftrack |") == 2
