"""The built-in detector's opening element, set for the footage (TrackerConfig.open_size).

By default it follows the frame's rows (``BlobConfig.kernel_sizes``); the element that works
follows the people's size and the video's noise instead (docs/detection.md, "Known limit"), so
the tracker and ``pftrack track --open-size`` let a user set it.
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.cli import build_parser
from pftrack.cli._options import tracker_config
from pftrack.synthetic import make_scene
from pftrack.tracking import MultiObjectTracker, TrackerConfig, track_frames


@pytest.mark.parametrize("value", [0, -3, 256, True, 2.5, "3"])
def test_bad_open_size_is_refused(value):
    with pytest.raises(ValueError, match="open_size"):
        TrackerConfig(open_size=value)


@pytest.mark.parametrize(("size", "rows", "expected"), [(None, 720, 7), (3, 720, 3), (9, 360, 9)])
def test_the_detector_opens_with_the_configured_element(size, rows, expected):
    tracker = MultiObjectTracker(TrackerConfig(open_size=size), rng=0)
    blobs = tracker.detector._blobs.config
    assert blobs.kernel_sizes(rows)[0] == expected
    assert blobs.kernel_sizes(rows)[1] == max(3, round(rows / 72)) | 1  # closing unchanged


def test_the_element_changes_the_run_and_its_default_is_the_rows_rule():
    scene = make_scene(n_frames=30, rng=2)
    default = track_frames(scene.frames, rng=0)
    same = track_frames(scene.frames, config=TrackerConfig(open_size=3), rng=0)  # 360 rows: 3
    wide = track_frames(scene.frames, config=TrackerConfig(open_size=9), rng=0)
    assert np.array_equal(default.rows, same.rows)
    assert not np.array_equal(default.rows, wide.rows)


def test_cli_open_size():
    parser = build_parser()
    args = parser.parse_args(["track", "video.avi", "--out", "t.txt", "--open-size", "3"])
    assert tracker_config(args).open_size == 3
    args = parser.parse_args(["track", "video.avi", "--out", "t.txt"])
    assert tracker_config(args).open_size is None  # 0, the default: from the frame's rows
    with pytest.raises(SystemExit) as e:
        parser.parse_args(["track", "video.avi", "--out", "t.txt", "--open-size", "300"])
    assert e.value.code == 2
