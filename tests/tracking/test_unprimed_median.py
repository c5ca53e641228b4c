"""An unprimed Tracker loop's first frames are refined against the median of the frames so far.

docs/tracking.md, "A loop without prime, second candidate": before each of the first
``prime_frames`` frames of a run that ``prime`` did not start (given detections, box refinement
on), the background model is primed from the frames taken so far, this one included.
"""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import pftrack
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking.api import xywh_to_xyxy_dets

N_FRAMES, PRIME = 40, 10


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=N_FRAMES, n_walkers=3, rng=3)


@pytest.fixture(scope="module")
def dets(scene):
    by_frame = group_by_frame(scene.truth)
    rows = [by_frame.get(f, np.zeros((0, 10))) for f in range(1, N_FRAMES + 1)]
    return [xywh_to_xyxy_dets(np.column_stack([r[:, 2:6], np.ones(len(r))])) for r in rows]


def tracker(**kwargs):
    # prime_frames 10 (frame_rate 10, prime 1 s): the window ends inside the scene
    return pftrack.Tracker(frame_rate=10.0, prime=PRIME / 10.0, **kwargs)


def masks_and_backgrounds(t, frames, dets, after=None):
    """Each frame's foreground mask and, after it, the background; `after(k)` past frame k."""
    out = []
    for k, (f, d) in enumerate(zip(frames, dets, strict=True), start=1):
        t.update(d, f)
        inner = t.tracker
        out.append((inner.last_mask.copy(), inner.detector.model.background.copy()))
        if after is not None:
            after(k)
    return out


def reference(frames):
    """A detector primed with frames[:k] compares frame k with: the masks a primed run gets."""
    fresh = tracker().tracker.detector  # the run's settings, made unused
    out = []
    for k in range(1, len(frames) + 1):
        if k <= PRIME:
            d = copy.deepcopy(fresh)
            d.prime(frames[:k])
        mask, _ = d.foreground(frames[k - 1])
        out.append((mask, d.model.background.copy()))
    return out


def test_each_frame_of_the_window_is_compared_with_the_median_so_far(scene, dets):
    """Frame k <= prime_frames: the mask of a detector primed with frames 1..k; past the
    window the model goes on from the median of all of them. Unprimed, frame 2 was compared
    with frame 1 (the running mean of the first frames, the people in it included)."""
    got = masks_and_backgrounds(tracker(), scene.frames, dets)
    want = reference(scene.frames)
    for k, ((m, b), (wm, wb)) in enumerate(zip(got, want, strict=True), start=1):
        np.testing.assert_array_equal(m, wm, err_msg=f"mask of frame {k}")
        np.testing.assert_array_equal(b, wb, err_msg=f"background after frame {k}")


def rows(t, frames, dets):
    for f, d in zip(frames, dets, strict=True):
        t.update(d, f)
    return t.finalize()


@pytest.mark.parametrize(
    "kwargs",
    [{"primed": True}, {"refine": False}, {"detector": "mog2"}, {"detector": "knn"}],
    ids=["primed", "refine-off", "mog2", "knn"],
)
def test_runs_the_rule_leaves_alone_are_unchanged(scene, dets, kwargs):
    """A primed run, ``refine=False`` and OpenCV's models: the rows of the code before."""
    kwargs = dict(kwargs)
    primed = kwargs.pop("primed", False)
    out = []
    for off in (False, True):
        t = tracker(**kwargs)
        if primed:
            t.prime(scene.frames[:PRIME])
        if off:
            t._no_median_background()
        out.append(rows(t, scene.frames, dets))
    np.testing.assert_array_equal(out[0], out[1])


@pytest.mark.filterwarnings("ignore:frame 4. dets=None runs the built-in")
def test_the_built_in_detector_stops_the_rule(scene, dets):
    """``dets=None`` on a frame of the window: from there the model learns as before (as if
    the rule had stopped after the frame before)."""
    with_none = list(dets)
    with_none[3] = None
    t = tracker()
    a = masks_and_backgrounds(t, scene.frames, with_none)
    t = tracker()

    def stop(k):
        if k == 3:
            t._no_median_background()

    b = masks_and_backgrounds(t, scene.frames, with_none, after=stop)
    c = masks_and_backgrounds(tracker(), scene.frames, dets)
    for (m, g), (wm, wg) in zip(a, b, strict=True):
        np.testing.assert_array_equal(m, wm)
        np.testing.assert_array_equal(g, wg)
    assert not np.array_equal(a[5][1], c[5][1])  # the rule went on without the None


def test_frames_read_into_one_buffer_are_kept_as_frames(scene, dets):
    """A loop reading every frame into one array (``cap.read(buffer)``): the frames kept for
    the median are copies, not the buffer (whose median would be the last frame alone)."""
    buffer = np.empty_like(scene.frames[0])
    t = tracker()
    for f, d in zip(scene.frames, dets, strict=True):
        np.copyto(buffer, f)
        t.update(d, buffer)
    np.testing.assert_array_equal(t.finalize(), rows(tracker(), scene.frames, dets))


def test_a_checkpoint_inside_the_window_keeps_its_frames(scene, dets):
    """Pickled at frame 5 and restored, the run goes on as if it had not stopped; a checkpoint
    made before the rule (no kept frames) goes on learning as it did then."""
    whole = rows(tracker(), scene.frames, dets)
    t = tracker()
    for f, d in zip(scene.frames[:5], dets[:5], strict=True):
        t.update(d, f)
    restored = pickle.loads(pickle.dumps(t))
    np.testing.assert_array_equal(rows(restored, scene.frames[5:], dets[5:]), whole)
    old = pickle.loads(pickle.dumps(t))
    del old.__dict__["_learning"], old.__dict__["_probe"]  # a checkpoint before the rule
    off = tracker()
    for f, d in zip(scene.frames[:5], dets[:5], strict=True):
        off.update(d, f)
    off._no_median_background()
    np.testing.assert_array_equal(
        rows(old, scene.frames[5:], dets[5:]), rows(off, scene.frames[5:], dets[5:])
    )
