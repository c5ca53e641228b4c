"""pftrack.Tracker checkpoints (pickle, copy) under threads, refused copies and prime's frames."""

from __future__ import annotations

import copy
import pickle
import re
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

import pftrack
from pftrack.integrations.supervision import SupervisionTracker
from pftrack.synthetic import make_scene

from .test_working_resolution import truth_dets

IN_USE = r"this Tracker is in use by another thread"
CLONES: dict[str, Callable[[Any], Any]] = {
    "deepcopy": copy.deepcopy,
    "pickle": lambda t: pickle.loads(pickle.dumps(t)),
}


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=30, rng=1)


class Held:
    """Holds the inner tracker's ``update`` open on another thread until released."""

    def __init__(self, tracker: pftrack.Tracker, dets: np.ndarray, frame: np.ndarray) -> None:
        self.inside, self.leave = threading.Event(), threading.Event()
        real = tracker._tracker.update

        def held(*args: Any, **kwargs: Any) -> Any:
            self.inside.set()
            assert self.leave.wait(10)
            return real(*args, **kwargs)

        tracker._tracker.update = held
        self.tracker = tracker
        self.thread = threading.Thread(target=tracker.update, args=(dets, frame))

    def __enter__(self) -> Held:
        self.thread.start()
        assert self.inside.wait(10)
        return self

    def __exit__(self, *exc: object) -> None:
        self.leave.set()
        self.thread.join()
        del self.tracker._tracker.update


@pytest.mark.parametrize("how", sorted(CLONES))
def test_a_checkpoint_is_refused_while_update_runs_on_another_thread(scene, how):
    # was: a checkpoint of frame_count 76 with the inner tracker at 77, and the copy failed in
    # finalize much later (smooth_tracks: duplicate rows)
    dets = truth_dets(scene)
    a = pftrack.Tracker()
    for k in range(10):
        a.update(dets[k], scene.frames[k])
    with Held(a, dets[10], scene.frames[10]):
        with pytest.raises(RuntimeError, match=rf"^Tracker\.__\w+__ \(.*\): {IN_USE}"):
            CLONES[how](a)
        with pytest.raises(RuntimeError, match=rf"^Tracker\.__getstate__: {IN_USE}"):
            a.__getstate__()
    assert a.frame_count == 11
    b = CLONES[how](a)  # free again: a consistent checkpoint that goes on as the original
    for k in range(11, len(scene.frames)):
        np.testing.assert_array_equal(
            a.update(dets[k], scene.frames[k]), b.update(dets[k], scene.frames[k])
        )
    np.testing.assert_array_equal(a.finalize(), b.finalize())


class Blocking:
    """An attribute whose copy or pickle waits: a checkpoint caught half taken."""

    def __init__(self) -> None:
        self.inside, self.leave = threading.Event(), threading.Event()

    def _wait(self) -> None:
        self.inside.set()
        assert self.leave.wait(10)

    def __reduce__(self) -> tuple[Any, ...]:
        self._wait()
        return (object, ())

    def __deepcopy__(self, memo: dict[int, Any]) -> object:
        self._wait()
        return object()


@pytest.mark.parametrize("how", sorted(CLONES))
def test_update_is_refused_while_a_checkpoint_is_being_taken(scene, how):
    # the state is walked inside the guard, not only handed out by __getstate__
    dets = truth_dets(scene)
    a = pftrack.Tracker()
    a.update(dets[0], scene.frames[0])
    a._probe = probe = Blocking()
    taking = threading.Thread(target=CLONES[how], args=(a,))
    taking.start()
    try:
        assert probe.inside.wait(10)
        with pytest.raises(RuntimeError, match=rf"^Tracker\.update: {IN_USE}"):
            a.update(dets[1], scene.frames[1])
    finally:
        probe.leave.set()
        taking.join()
    assert a.frame_count == 1
    a.update(dets[1], scene.frames[1])


def test_a_shallow_copy_is_refused(scene):
    # was: copy.copy shared the inner tracker, writer and background, with a lock of its own
    a = pftrack.Tracker()
    a.update(truth_dets(scene)[0], scene.frames[0])
    with pytest.raises(TypeError, match=r"^copy\.copy\(Tracker\) would share .*copy\.deepcopy"):
        copy.copy(a)
    s = SupervisionTracker()
    with pytest.raises(TypeError, match=r"^copy\.copy\(SupervisionTracker\) would share"):
        copy.copy(s)
    assert copy.deepcopy(s).tracker is not s.tracker


def test_a_deep_copy_keeps_shared_references(scene):
    # deepcopy's memo is kept: an object referring to the tracker gets the copy's
    a = pftrack.Tracker()
    a.update(truth_dets(scene)[0], scene.frames[0])
    pair = copy.deepcopy([a, a])
    assert pair[0] is pair[1] and pair[0] is not a


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"detector": "mog2"}, "detector='mog2' cannot be checkpointed (pickle/deepcopy) once"),
        ({"detector": "knn"}, "detector='knn' cannot be checkpointed (pickle/deepcopy) once"),
    ],
)
@pytest.mark.parametrize("how", sorted(CLONES))
def test_an_uncopyable_run_names_its_option(scene, options, message, how):
    # was: TypeError: cannot pickle 'pftrack._core.RJMCMCTracker' object (or cv2's subtractor)
    a = pftrack.Tracker(**options)
    CLONES[how](a)  # before the first frame: copied
    a.update(None, scene.frames[0])
    with pytest.raises(TypeError, match="^" + re.escape(message)):
        CLONES[how](a)
    a.update(None, scene.frames[1])  # the refusal left the run as it was


@pytest.mark.parametrize("detector", ["mog2", "knn"])
def test_a_primed_opencv_background_names_its_option(scene, detector):
    a = pftrack.Tracker(detector=detector)
    a.prime(scene.frames[:3])
    with pytest.raises(TypeError, match=rf"^detector='{detector}' cannot be checkpointed"):
        pickle.dumps(a)


def test_prime_refuses_frames_of_two_sizes(scene):
    # was: a 100x100 frame accepted silently; a cropped one an IndexError in frame_gain
    a = scene.frames[0]
    for odd in (np.zeros((100, 100, 3), np.uint8), a[:, :400]):
        t = pftrack.Tracker()
        frames: Iterator[np.ndarray] = iter([a, a, odd])
        h, w = odd.shape[:2]
        with pytest.raises(
            ValueError,
            match=rf"^prime frame 2 is {w}x{h}, frame 0 480x360 \(the frames of one run are one "
            r"size\)$",
        ):
            t.prime(frames)
        t.prime([a, a])  # nothing was taken: prime is still open
        t.update(None, a)


@pytest.mark.parametrize("max_side", [None, 64])
@pytest.mark.filterwarnings("ignore:frame 1 is blank")  # the new run's placeholder frame
def test_a_new_frame_size_names_reset(scene, max_side):
    t = pftrack.Tracker(max_side=max_side)
    t.update(None, scene.frames[0])
    with pytest.raises(
        ValueError,
        match=r"^frame is 100x100, the run's earlier frames 480x360 \(.*one size per run; call "
        r"reset\(\) or use a new Tracker before a new video\)$",
    ):
        t.update(None, np.zeros((100, 100, 3), np.uint8))
    t.reset()
    t.update(None, np.zeros((100, 100, 3), np.uint8))


# A run checkpointed at each pickle protocol and resumed, in a child process: pickle at
# protocols 0 and 1 aborted the interpreter (SIGABRT, pybind11's "instance allocation failed:
# new instance has no pybind11-registered base types") once the background model existed,
# which would take pytest down with it.
RESUME_AT_EVERY_PROTOCOL = """
import pickle
import numpy as np
import pftrack
from pftrack.synthetic import make_scene

scene = make_scene(n_frames=24, rng=1)
truth = scene.truth

def dets(k):
    r = truth[truth[:, 0] == k + 1]
    return np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6], np.full(len(r), 0.95)])

for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
    for primed, at in ((True, 0), (False, 8)):  # after prime(); after the first updates
        a = pftrack.Tracker()
        if primed:
            a.prime(scene.frames[:5])
        for k in range(at):
            a.update(dets(k), scene.frames[k])
        b = pickle.loads(pickle.dumps(a, protocol=protocol))
        for k in range(at, len(scene.frames)):
            out_a, out_b = a.update(dets(k), scene.frames[k]), b.update(dets(k), scene.frames[k])
            assert out_a.tobytes() == out_b.tobytes(), (protocol, primed, k)
        rows = a.finalize()
        assert len(rows) and rows.tobytes() == b.finalize().tobytes(), (protocol, primed)
    print(protocol, "resumed", flush=True)
"""


def test_a_checkpoint_at_every_pickle_protocol_resumes_byte_for_byte():
    run = subprocess.run(
        [sys.executable, "-c", RESUME_AT_EVERY_PROTOCOL], capture_output=True, text=True,
        timeout=600,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split("\n")[:-1] == [
        f"{p} resumed" for p in range(pickle.HIGHEST_PROTOCOL + 1)
    ]


def test_a_checkpoint_of_one_shared_speed_median_resumes_as_the_run_of_per_class_ones(scene):
    """A checkpoint pickled when every class shared one speed median and gain (before 5
    December) loads into per-class ones and resumes exactly as a run of the current code."""
    from pftrack.tracking.tracker import MultiObjectTracker

    dets = truth_dets(scene)
    tracker = pftrack.Tracker(frame_rate=10.0, seed=0)
    for k in range(20):
        tracker.update(dets[k], scene.frames[k])
    old = copy.deepcopy(tracker)
    state = old._tracker.__dict__
    speeds = state.pop("_speeds")
    state["_speeds"], state["_gain"] = speeds[0], state.pop("_gains").get(0, 1.0)
    inner = MultiObjectTracker.__new__(MultiObjectTracker)
    inner.__setstate__(pickle.loads(pickle.dumps(old._tracker.__getstate__())))
    old._tracker = inner
    assert isinstance(inner._speeds, dict) and "_gain" not in inner.__dict__
    for k in range(20, 30):
        np.testing.assert_array_equal(
            old.update(dets[k], scene.frames[k]), tracker.update(dets[k], scene.frames[k])
        )
    np.testing.assert_array_equal(old.finalize(), tracker.finalize())


def test_a_checkpoint_of_one_pooled_birth_threshold_resumes(scene):
    """A checkpoint pickled when every class shared one birth threshold (before 5 December:
    no per-class scores) loads, and its classes take the pooled threshold; a run without
    classes resumes exactly as one of the current code."""
    from pftrack.tracking.tracker import MultiObjectTracker

    rng = np.random.default_rng(0)
    dets = truth_dets(scene)
    for d in dets:  # scores under birth_score, whose quartile is the threshold
        d[:, 4] = rng.uniform(0.3, 0.9, len(d))
    tracker = pftrack.Tracker(frame_rate=10.0, seed=0)
    for k in range(20):
        tracker.update(dets[k], scene.frames[k])
    old = copy.deepcopy(tracker)
    state = old._tracker.__getstate__()
    del state["_class_birth_scores"], state["_class_birth_levels"]
    inner = MultiObjectTracker.__new__(MultiObjectTracker)
    inner.__setstate__(pickle.loads(pickle.dumps(state)))
    old._tracker = inner
    pooled = tracker._tracker.birth_threshold()
    assert inner.birth_threshold(0) == inner.birth_threshold(2) == pooled
    for k in range(20, 30):
        np.testing.assert_array_equal(
            old.update(dets[k], scene.frames[k]), tracker.update(dets[k], scene.frames[k])
        )
        assert old._tracker.birth_threshold() == tracker._tracker.birth_threshold()
    np.testing.assert_array_equal(old.finalize(), tracker.finalize())


@pytest.mark.parametrize("given", [True, False])
@pytest.mark.parametrize("how", sorted(CLONES))
def test_a_joint_sampler_run_resumes_from_a_checkpoint(scene, how, given):
    """sampler='rjmcmc' mid-run: the copy's chain has the original's identities, samples,
    next id, seed and step, so both go on with the same rows. Was: TypeError, the chain could
    not be copied once it had seen a frame."""
    dets = truth_dets(scene)
    a = pftrack.Tracker(sampler="rjmcmc", seed=2)
    for k in range(12):
        a.update(dets[k] if given else None, scene.frames[k])
    b = CLONES[how](a)
    assert b._tracker._joint._filter._core is not a._tracker._joint._filter._core
    for k in range(12, 30):
        x = a.update(dets[k] if given else None, scene.frames[k])
        y = b.update(dets[k] if given else None, scene.frames[k])
        np.testing.assert_array_equal(x, y)
    rows = a.finalize()
    assert len(rows) and np.array_equal(rows, b.finalize())
