"""The detections' check warns through pftrack._warn: held inside ``update``, given whole.

``check_detections`` called ``warnings.warn`` itself: inside ``MultiObjectTracker.update``
(given ``[left, top, w, h, score]`` boxes unchecked; ``Tracker`` checks its own) its warning
escaped the hold (:class:`pftrack._warn.Held`), named a line of pftrack's, and under ``-W
error`` was raised half-way through the frame, the tracker refusing every later frame as
interrupted. tests/test_layout.py keeps every module on pftrack._warn.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from pftrack import MultiObjectTracker, TrackerConfig
from pftrack.detection import check_detections
from pftrack.synthetic import make_scene

# [left, top, w, h, score]: one box in the 160x120 frame, one wholly outside it
BOXES = np.array([[40.0, 30.0, 20.0, 50.0, 0.9], [400.0, 300.0, 20.0, 50.0, 0.9]])


def _tracker() -> MultiObjectTracker:
    return MultiObjectTracker(TrackerConfig(), rng=0)


def test_the_warning_inside_update_names_the_users_line() -> None:
    frame = make_scene(n_frames=1, width=160, height=120, rng=0).frames[0]
    tracker = _tracker()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tracker.update(frame, BOXES)
    (said,) = [w for w in caught if "wholly outside" in str(w.message)]
    assert said.filename == __file__, said


def test_made_an_error_it_leaves_a_usable_tracker() -> None:
    frames = make_scene(n_frames=2, width=160, height=120, rng=0).frames
    tracker = _tracker()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="wholly outside") as raised:
            tracker.update(frames[0], BOXES)
    said = [str(raised.value), *getattr(raised.value, "__notes__", [])]
    assert any("1 detection(s) wholly outside the 160x120 frame" in s for s in said), said
    assert tracker.frame_index == 1  # the frame was taken whole
    tracker.update(frames[1], BOXES[:1])  # not refused as interrupted
    assert tracker.frame_index == 2


def test_called_alone_it_names_the_callers_line() -> None:
    xywh = np.array([[400.0, 300.0, 20.0, 50.0]])
    with pytest.warns(UserWarning, match="wholly outside") as said:
        check_detections(xywh, (120, 160))
    assert said[0].filename == __file__
