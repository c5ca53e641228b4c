"""Whole-pipeline speed: ``pftrack track`` on PETS09-S2L1, decode + detection + tracking.

pytest bench/test_tracking.py --benchmark-enable --benchmark-only --benchmark-group-by=group

The 768x576 case first writes the video upscaled to a temporary MJPG file, so decoding the
larger frames is timed too. Each group holds the paper's fused detector and OpenCV's MOG2 in
the same pipeline (same tracker, 100 particles per object): the ratio of their means is the
detector's share of the speed. Frames per second go to ``extra_info["fps"]``.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cv2
import pytest

from bench.conftest import DATA
from pftrack.run import track_frames
from pftrack.tracker import TrackerConfig

VIDEO = DATA / "pets09-s2l1" / "video.avi"
SIZES = {"480x360": (480, 360), "768x576": (768, 576)}

pytestmark = pytest.mark.skipif(not VIDEO.is_file(), reason=f"no PETS09-S2L1 video at {VIDEO}")


@pytest.fixture(scope="module", params=list(SIZES))
def video(request, tmp_path_factory) -> tuple[str, Path]:
    size = SIZES[request.param]
    if size == (480, 360):
        return request.param, VIDEO
    out = tmp_path_factory.mktemp("video") / f"pets_{request.param}.avi"
    cap = cv2.VideoCapture(str(VIDEO))
    writer = cv2.VideoWriter(str(out), cv2.VideoWriter_fourcc(*"MJPG"), 7.0, size)
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        writer.write(cv2.resize(frame, size, interpolation=cv2.INTER_LINEAR))
    cap.release()
    writer.release()
    return request.param, out


@pytest.mark.parametrize("detector", ["paper", "mog2"])
def test_track_video(benchmark, video, detector):
    name, path = video
    benchmark.group = f"pftrack track PETS09 {name}"
    config = replace(TrackerConfig(), detector=detector)
    run = benchmark.pedantic(lambda: track_frames(path, config=config, rng=0, show_progress=False), rounds=2, iterations=1)
    assert run.n_frames == 795
    assert len(run.rows) > 1000  # people were tracked, not just frames decoded
    benchmark.extra_info["fps"] = round(run.n_frames / benchmark.stats.stats.mean, 1)
