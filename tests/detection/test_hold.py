"""People who stop: StopMemory (pftrack.detection.hold) and the detector holding them."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.boxes import iou_xywh
from pftrack.detection import PaperConfig, make_detector
from pftrack.detection.hold import HOLD_MISSES, STILL_FRAMES, StopMemory
from pftrack.synthetic import _paste, _sprite, make_scene


def _walk_then_stand(memory: StopMemory, walk: int, stand: int) -> list[int]:
    """A 30 x 80 box walking 3 px a frame, then standing: how many boxes are held each frame."""
    held = []
    for f in range(walk + stand):
        x = 10.0 + 3.0 * min(f, walk)
        memory.observe(np.array([[x, 50.0, 30.0, 80.0]]))
        held.append(len(memory.held))
    return held


def test_an_object_that_walked_and_stopped_is_held_until_the_time_limit():
    memory = StopMemory(hold_frames=200)
    held = _walk_then_stand(memory, walk=30, stand=300)
    # walking, and the first STILL_FRAMES frames standing: not held (a walker's pixels are
    # learnt as before); then held, until hold_frames after the last move
    # it moves by half its width (15 px) every 5 frames, last at index 30 (where it stops)
    on = [f for f, n in enumerate(held) if n]
    assert on == list(range(30 + STILL_FRAMES, 30 + 200 + 1))
    assert len(memory.still) == 1  # the size model does not learn from it


def _pace(f: int, moves: list[tuple[int, int]]) -> float:
    """x of an object 3 px a frame during the frames [start, stop) of `moves`, still between."""
    return 10.0 + 3.0 * sum(max(0, min(f, stop) - start) for start, stop in moves)


def test_held_and_still_skip_the_test_only_where_it_finds_nothing():
    # `_stand_at` (from observe) lets held / still return at once before any object that
    # walked can have stood STILL_FRAMES: the same boxes as the test of every object (a twin
    # whose _stand_at is 0, as a memory pickled before it was kept), frame by frame
    rng = np.random.default_rng(3)
    fast, full = StopMemory(hold_frames=120), StopMemory(hold_frames=120)
    skipped = held = still = 0
    for f in range(420):
        boxes = [[_pace(f, [(0, 40), (200, 260)]), 50.0, 30.0, 80.0]]  # walks, stands, again
        if 100 <= f < 330:  # comes, walks, stands, leaves
            boxes.append([_pace(f, [(100, 150)]) + 200.0, 150.0, 28.0, 76.0])
        boxes.append([600.0, 40.0, 20.0, 20.0])  # never moves
        b = np.array(boxes) + rng.normal(0.0, 0.3, (len(boxes), 4))
        fast.observe(b)
        full.observe(b)
        full._stand_at = 0
        skipped += f + 1 < fast._stand_at
        np.testing.assert_array_equal(fast.held, full.held)
        np.testing.assert_array_equal(fast.still, full.still)
        assert fast.held.shape[1:] == fast.still.shape[1:] == (4,)
        held += len(fast.held) > 0
        still += len(fast.still) > 0
    assert skipped > 50 and held > 100 and still > 100  # both paths taken, boxes found


def test_an_object_that_never_moved_is_never_held():
    # a patch of changed light, a ghost: its box stays where it is
    memory = StopMemory(hold_frames=1000)
    held = _walk_then_stand(memory, walk=0, stand=300)
    assert held == [0] * 300
    assert len(memory.still) == 0


def test_a_box_that_changes_size_is_not_a_move():
    # merged with a passer-by: the box doubles its width to one side, its centre moves by
    # half its former width; it did not walk
    memory = StopMemory(hold_frames=1000)
    for f in range(200):
        w = 60.0 if 20 <= f < 40 else 30.0
        memory.observe(np.array([[10.0, 50.0, w, 80.0]]))
        assert len(memory.held) == 0


def test_a_passer_by_who_merged_with_a_stander_does_not_take_them_along():
    """Regression (lowseeds; standing_long seed 1, 600 frames): a passer-by walking past a
    person standing merges with them; the merged box follows the passer-by, and when the two
    split (the stander's part partly hidden), the passer-by's part overlapped the merged box
    more and took the stander's place: the stander's part started as an object that never
    moved, was never held, and was absorbed. The part where the stander stands is theirs."""
    memory = StopMemory(hold_frames=1000)
    _walk_then_stand(memory, walk=30, stand=100)  # stands at [100, 50, 30, 80]
    stander = np.array([100.0, 50.0, 30.0, 80.0])
    for px in np.arange(157.0, 40.0, -3.0):  # a 30 px wide passer-by walking left past them
        if px >= 130.0 or px + 30.0 <= 100.0:
            boxes = [[px, 52.0, 30.0, 80.0], stander]  # apart
        elif px >= 85.0:
            left, right = min(100.0, px), max(130.0, px + 30.0)
            boxes = [[left, 50.0, right - left, 82.0]]  # one blob
        else:  # split: the passer-by, and the stander's part to its right
            boxes = [[px, 52.0, 30.0, 80.0], [px + 30.0, 50.0, 100.0 - px, 80.0]]
        memory.observe(np.array(boxes))
    held = memory.held
    assert len(held) == 1 and iou_xywh(stander, held).max() > 0.99, held


def test_a_missed_object_is_held_then_forgotten():
    memory = StopMemory(hold_frames=1000)
    _walk_then_stand(memory, walk=30, stand=100)
    for _ in range(HOLD_MISSES):
        memory.observe(np.zeros((0, 4)))
        assert len(memory.held) == 1  # its last box, while it may come back
    memory.observe(np.zeros((0, 4)))
    assert len(memory.held) == 0
    mask = memory.hold_mask((200, 300))
    assert mask is None


def test_hold_mask_and_off():
    memory = StopMemory(hold_frames=1000)
    _walk_then_stand(memory, walk=30, stand=100)
    mask = memory.hold_mask((200, 300))
    assert mask is not None and mask.dtype == np.uint8
    x, y, w, h = memory.held[0].astype(int)
    assert mask.sum() == w * h and mask[y : y + h, x : x + w].all()
    off = StopMemory(hold_frames=0)
    _walk_then_stand(off, walk=30, stand=100)
    assert len(off.held) == 0 and off.hold_mask((200, 300)) is None


def test_hold_frames_is_checked():
    with pytest.raises(ValueError, match="hold_frames"):
        PaperConfig(hold_frames=-1)
    with pytest.raises(TypeError, match="hold_frames"):
        PaperConfig(hold_frames=2.5)  # type: ignore[arg-type]


def _stander_found(hold_frames: int, stand: int = 400) -> list[bool]:
    """make_scene's background and a walker who walks in 40 frames, then stands `stand`."""
    scene = make_scene(n_frames=40 + stand, n_walkers=1, rng=0, occluder=False)
    gen = np.random.default_rng(7)
    look = ((40, 180, 40), (60, 40, 30), (120, 160, 210))
    sprites = [_sprite(30, 80, *look, phase, gen) for phase in (0, 1)]
    det = make_detector("paper", hold_frames=hold_frames)
    det.prime([scene.background])
    found = []
    for f, frame in enumerate(scene.frames):
        walking = f < 40
        sprite = sprites[(f // 3) % 2 if walking else 0]
        box = _paste(frame, *sprite, 3.0 * min(f, 40), 220.0)
        d = det.detect(frame)
        found.append(bool(len(d.boxes)) and iou_xywh(box, d.boxes).max() >= 0.5)
    return found[40:]


@pytest.mark.slow
def test_a_person_who_stops_for_long_stays_detected():
    """Regression (standlong): a walker who stands 400 frames was absorbed by alpha_fg and lost
    after about 250 of them; held once still for STILL_FRAMES, found on all 400."""
    held = _stander_found(1000)
    assert sum(held) == 400, sum(held)
    unheld = _stander_found(0)  # the detector before: lost for the last ~150 frames
    assert sum(unheld[-100:]) == 0, sum(unheld)


def test_the_hold_is_off_by_default_and_reaches_the_detector_from_the_tracker_config():
    # off by default (it cost PETS09 re-encoded as JPEG 8 IDF1: docs/detection.md); a
    # tracker's TrackerConfig.hold_frames is its built-in detector's
    from pftrack.tracking import MultiObjectTracker, TrackerConfig

    assert PaperConfig().hold_frames == 0 and TrackerConfig().hold_frames == 0
    for hold in (0, 700):
        tracker = MultiObjectTracker(TrackerConfig(hold_frames=hold))
        assert tracker._ensure_detector().config.hold_frames == hold
    with pytest.raises(ValueError, match="hold_frames 5 needs detector 'paper'"):
        TrackerConfig(hold_frames=5, detector="mog2")
    with pytest.raises(TypeError, match="hold_frames"):
        TrackerConfig(hold_frames=2.5)  # type: ignore[arg-type]


@pytest.mark.xfail(
    strict=True,
    reason="a slow walker whose box grows past HOLD_SIZE has his drift forgiven (the anchor "
    "takes the new box) and is held while still walking: PETS09 as JPEG, docs/detection.md "
    "(a rule judging stillness from the box's path over 50 frames passes this test, but was "
    "measured and not adopted: holdrobust)",
)
def test_a_slow_walker_whose_box_grows_is_not_held_while_walking():
    # PETS09's person 1 (frames 488-548): walks in, then drifts 0.3 px a frame, his box 31
    # wide growing from 57 to 72 high (x1.26, legs found again); in the 50 frames before the
    # hold would begin he moved more than half his width
    memory = StopMemory(hold_frames=1000)
    _walk_then_stand(memory, walk=30, stand=0)
    held = []
    for f in range(STILL_FRAMES + 10):
        h = 57.0 if f < 35 else 72.0
        memory.observe(np.array([[100.0, 50.0 + 0.3 * f, 31.0, h]]))
        held.append(len(memory.held))
    assert held == [0] * len(held)


@pytest.mark.xfail(
    strict=True,
    reason="the held box is the object's box now: passers-by who merge with a person standing "
    "are held with them (PETS09 as JPEG, frames 588-615: 31 x 73 -> 30 x 136); holding the "
    "box where the person stands instead was measured worse (holdrobust, docs/detection.md)",
)
def test_passers_by_merging_with_a_held_person_are_not_held():
    memory = StopMemory(hold_frames=1000)
    _walk_then_stand(memory, walk=30, stand=100)  # held at [100, 50, 30, 80]
    assert len(memory.held) == 1
    for _ in range(20):  # two passers-by behind them: one blob, as tall again, same width
        memory.observe(np.array([[100.0, -30.0, 30.0, 160.0]]))
    held = memory.held
    assert len(held) == 1 and held[0, 3] <= 80.0, held
