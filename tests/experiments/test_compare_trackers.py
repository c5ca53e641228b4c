"""``experiments.compare_trackers`` on a MOT15 sequence without video: pftrack's row is the
drop-in tracker's, as ``experiments.public_detections`` scores it."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments import compare_trackers as ex
from experiments import public_detections
from experiments._common import data_root
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import read_mot
from pftrack.tracking import TrackerConfig, load_detections, track_frames


def test_a_sequence_without_video_is_scored_on_black_frames(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data_dir = data_root()
    folder = data_dir / "mot15-gt" / "KITTI-17"
    if not (folder / "det.txt").is_file():
        pytest.skip("mot15-gt/KITTI-17 is not in the data folder")
    code = ex.main(["--data", str(data_dir), "--seq", "KITTI-17", "--tracker", "pftrack",
                    "--detector", "public", "mog2", "--out", str(tmp_path)])  # fmt: skip
    assert code == 0
    row = next(r for r in capsys.readouterr().out.splitlines() if r.startswith("| pftrack |"))
    mota, idf1 = (float(v) for v in row.split("|")[4:6])
    # the same boxes through track_frames, as experiments.public_detections runs them
    frames = public_detections.black_frames(folder)
    dets = load_detections(folder / "det.txt")
    with public_detections.blank_frames_expected():
        run = track_frames(frames, detections=dets, config=TrackerConfig(), rng=0)
    s = evaluate_sequence(read_mot(folder / "gt.txt"), run.rows)
    assert (mota, idf1) == (round(100 * s.mot.mota, 1), round(100 * s.mot.idf1, 1))
    notes = (tmp_path / "trackers.md").read_text()
    assert "KITTI-17: no video, so no mog2 detections" in notes
