"""Fixtures shared by the experiments' tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments import public_detections
from experiments._common import data_root
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import read_mot, write_mot
from pftrack.synthetic import make_scene
from pftrack.tracking import TrackerConfig, load_detections, track_frames


@pytest.fixture(scope="module")
def data(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A data folder with one short sequence laid out like the real ones: ``tiny/img`` (12
    PNG frames, two walkers), ``tiny/gt.txt`` and ``tiny/det.txt`` (the truth, ids -1)."""
    root = tmp_path_factory.mktemp("data")
    scene = make_scene(n_frames=12, n_walkers=2, rng=4, occluder=False)
    folder = root / "tiny"
    folder.mkdir()
    scene.write_images(folder / "img", ext=".png")
    write_mot(folder / "gt.txt", scene.truth)
    dets = scene.truth.copy()
    dets[:, 1] = -1
    write_mot(folder / "det.txt", dets)
    return root


@pytest.fixture(scope="session")
def kitti17() -> tuple[Path, tuple[float, float]]:
    """The data folder, and MOTA / IDF1 (in %, 1 decimal) of ``track_frames`` on KITTI-17's
    public boxes and black frames, as ``experiments.public_detections`` runs it (what ``pftrack
    track`` writes). Skips when ``mot15-gt/KITTI-17`` is absent."""
    data_dir = data_root()
    folder = data_dir / "mot15-gt" / "KITTI-17"
    if not (folder / "det.txt").is_file():
        pytest.skip("mot15-gt/KITTI-17 is not in the data folder")
    frames = public_detections.black_frames(folder)
    dets = load_detections(folder / "det.txt")
    with public_detections.blank_frames_expected():
        run = track_frames(frames, detections=dets, config=TrackerConfig(), rng=0)
    s = evaluate_sequence(read_mot(folder / "gt.txt"), run.rows)
    return data_dir, (round(100 * s.mot.mota, 1), round(100 * s.mot.idf1, 1))
