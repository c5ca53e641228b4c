"""``experiments.compare_trackers`` on a MOT15 sequence without video: pftrack's row is the
drop-in tracker's, as ``experiments.public_detections`` scores it."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments import compare_trackers as ex


def test_a_sequence_without_video_is_scored_on_black_frames(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kitti17: tuple[Path, tuple[float, float]]
) -> None:
    data_dir, drop_in = kitti17
    code = ex.main(["--data", str(data_dir), "--seq", "KITTI-17", "--tracker", "pftrack",
                    "--detector", "public", "mog2", "--out", str(tmp_path)])  # fmt: skip
    assert code == 0
    row = next(r for r in capsys.readouterr().out.splitlines() if r.startswith("| pftrack |"))
    mota, idf1 = (float(v) for v in row.split("|")[4:6])
    assert (mota, idf1) == drop_in  # the same boxes through track_frames
    notes = (tmp_path / "trackers.md").read_text()
    assert "KITTI-17: no video, so no mog2 detections" in notes
