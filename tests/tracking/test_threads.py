"""MultiObjectTracker shared between threads: a second thread is refused, never mixed in."""

from __future__ import annotations

import copy
import pickle
import threading
from typing import Any

import numpy as np
import pytest

from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import MultiObjectTracker

IN_USE = r"this MultiObjectTracker is in use by another thread"


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=12, rng=2)


def truth_xywh(scene) -> list[np.ndarray]:
    """Per-frame (K, 5) left, top, width, height, score of the scene's truth."""
    by_frame = group_by_frame(scene.truth)
    return [
        np.column_stack([r[:, 2:6], np.ones(len(r))])
        if len(r := by_frame.get(f, np.zeros((0, 10))))
        else np.zeros((0, 5))
        for f in range(1, len(scene.frames) + 1)
    ]


def test_a_second_thread_is_refused_while_one_updates(scene):
    # was: both threads' frames went in, one after the other's (frame_index counted both),
    # until an inner object said "step_filters: filters[0] is in use" or "BackgroundModel.
    # global_gain: the object is in use", the run torn (a trial of two threads feeding one)
    dets = truth_xywh(scene)
    m = MultiObjectTracker(rng=0)
    serial = MultiObjectTracker(rng=0)
    inside, leave = threading.Event(), threading.Event()
    real = m._update
    first = threading.Thread(target=lambda: m.update(scene.frames[0], dets[0]))

    def held(*args: Any, **kwargs: Any) -> Any:  # the first thread waits inside its frame
        if threading.current_thread() is first:
            inside.set()
            assert leave.wait(10)
        return real(*args, **kwargs)

    m._update = held  # type: ignore[method-assign]
    first.start()
    try:
        assert inside.wait(10)
        for call in (
            lambda: m.update(scene.frames[0], dets[0]),
            lambda: m.prime([scene.frames[0]]),
            lambda: copy.deepcopy(m),
            lambda: pickle.dumps(m),
        ):
            with pytest.raises(RuntimeError, match=rf"^MultiObjectTracker\.\w+: {IN_USE}"):
                call()
    finally:
        leave.set()
        first.join(10)
    del m._update
    assert m.frame_index == 1  # the first thread's frame went in, the refused ones not
    serial.update(scene.frames[0], dets[0])
    for k in range(1, len(scene.frames)):  # free again, and the run is the serial one
        a, b = m.update(scene.frames[k], dets[k]), serial.update(scene.frames[k], dets[k])
        assert [(t.id, t.box_xywh.tolist()) for t in a] == [(t.id, t.box_xywh.tolist()) for t in b]


def test_a_copy_of_a_multi_object_tracker_goes_on_as_the_original(scene):
    dets = truth_xywh(scene)
    m = MultiObjectTracker(rng=0)
    for k in range(4):
        m.update(scene.frames[k], dets[k])
    assert "_busy" not in m.__getstate__()  # a lock is not copied: the copy is free
    for twin in (copy.deepcopy(m), pickle.loads(pickle.dumps(m))):
        a, b = copy.deepcopy(m), twin  # a's frames leave m at frame 4 for the next twin
        for k in range(4, len(scene.frames)):
            ra, rb = a.update(scene.frames[k], dets[k]), b.update(scene.frames[k], dets[k])
            assert [(t.id, t.box_xywh.tolist()) for t in ra] == [
                (t.id, t.box_xywh.tolist()) for t in rb
            ]
