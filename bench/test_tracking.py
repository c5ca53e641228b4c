"""Whole-pipeline speed: ``pftrack track`` on PETS09-S2L1, decode + detection + tracking.

pytest bench/test_tracking.py --benchmark-enable --benchmark-only --benchmark-group-by=group

The 768x576 case first writes the video upscaled to a temporary MJPG file, so decoding the
larger frames is timed too. Each group holds the paper's fused detector and OpenCV's MOG2 in
the same pipeline (same tracker, 100 particles per object): the ratio of their means is the
detector's share of the speed. Frames per second go to ``extra_info["fps"]`` (not under
``--benchmark-disable``, which runs each case once without timing it).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cv2
import pytest
from pytest_benchmark.fixture import BenchmarkFixture

from pftrack.io.opencv_io import opencv_name
from pftrack.tracking import TrackerConfig, track_frames

SIZES = {"480x360": (480, 360), "768x576": (768, 576)}


@pytest.fixture(scope="module")
def pets_video(pets_dir: Path) -> Path:
    video = pets_dir / "video.avi"
    if not video.is_file():
        pytest.skip(f"no PETS09-S2L1 video at {video}")
    return video


@pytest.fixture(scope="module", params=list(SIZES))
def video(
    request: pytest.FixtureRequest, pets_video: Path, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, Path]:
    size = SIZES[request.param]
    if size == (480, 360):
        return request.param, pets_video
    out = tmp_path_factory.mktemp("video") / f"pets_{request.param}.avi"
    with opencv_name(pets_video) as src, opencv_name(out) as dst:  # any name (opencv_io)
        cap = cv2.VideoCapture(src)
        writer = cv2.VideoWriter(dst, cv2.VideoWriter.fourcc(*"MJPG"), 7.0, size)
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        writer.write(cv2.resize(frame, size, interpolation=cv2.INTER_LINEAR))
    cap.release()
    writer.release()
    return request.param, out


@pytest.mark.parametrize("detector", ["paper", "mog2"])
def test_track_video(benchmark: BenchmarkFixture, video: tuple[str, Path], detector: str) -> None:
    name, path = video
    benchmark.group = f"pftrack track PETS09 {name}"
    config = replace(TrackerConfig(), detector=detector)
    run = benchmark.pedantic(
        lambda: track_frames(path, config=config, rng=0, show_progress=False),
        rounds=2,
        iterations=1,
    )
    assert run.n_frames == 795
    assert len(run.rows) > 1000  # people were tracked, not just frames decoded
    if benchmark.stats is not None:  # None under --benchmark-disable: nothing was timed
        benchmark.extra_info["fps"] = round(run.n_frames / benchmark.stats.stats.mean, 1)
