"""The tracker's own colour in its offline pass (stop 74; an option, off by default).

A tracker made with ``colour`` (e.g. ``"swap"``) keeps, for each row it writes, the
histogram it already holds (the matched detection's, which the association compared, or the
filter's reference while it coasts) and hands them to :func:`pftrack.tracking.smooth_tracks`
as ``histograms``: the fill's swap rule (:func:`pftrack.recovery.fill.swap_holes`) and, with
``"link"``, the linker's colour term read them instead of decoding the video again
(docs/recovery.md, "The tracker's own colour in the offline pass").
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import pftrack
from pftrack.particle_filter.colour import box_histograms, hsv_bins
from pftrack.recovery.linking import FLAG_COLUMN, RowColours, frame_histograms
from pftrack.tracking import smooth_tracks
from pftrack.tracking.track import Track
from pftrack.tracking.writer import TrackWriter
from tests.recovery.test_hand72_swap import BLUE, RED, _handed_over, _walkers
from tests.reference import kernels as ref

HOLE = range(10, 14)


def _cxcywh(b: np.ndarray) -> np.ndarray:
    b = np.atleast_2d(b)
    return np.column_stack([b[:, 0] + b[:, 2] / 2, b[:, 1] + b[:, 3] / 2, b[:, 2], b[:, 3]])


def _colour(frame: np.ndarray, box: np.ndarray) -> np.ndarray:
    """The association's call on a box of a frame (MultiObjectTracker._update, step 2)."""
    return box_histograms(hsv_bins(frame), _cxcywh(box), "uniform")[0]


def _reported(frames: list[np.ndarray], rows: np.ndarray, colour: str | None) -> np.ndarray:
    """`rows` written by a TrackWriter as a tracker reports them, frame by frame: each row a
    matched detection with the association's histogram of its box."""
    w = TrackWriter(colour=colour)
    for f in range(1, len(frames) + 1):
        here = rows[rows[:, 0] == f]
        w.add(
            f,
            [
                Track(int(r[1]), r[2:6].copy(), 1.0, 0, f, 0, detection_box=r[2:6].copy(),
                      colour=_colour(frames[f - 1], r[2:6]))
                for r in here
            ],
        )  # fmt: skip
    return w.result()


def _rows_in(out: np.ndarray, frames: range) -> np.ndarray:
    return out[np.isin(out[:, 0], list(frames))]


def test_a_hand_over_between_two_colours_is_left_with_the_trackers_colour() -> None:
    """Red and blue walkers side by side whose ids the tracker hands to each other across a
    4-frame hole: without colour the pass draws both paths across the hole; with the
    tracker's histograms (rule on) both holes stay, nothing is drawn, ids are kept."""
    frames, truth = _walkers()
    rows = _handed_over(truth, HOLE)
    plain = _reported(frames, rows, None)
    assert len(_rows_in(plain, HOLE)) == 2 * len(HOLE)  # filled: the jump is plausible
    for use in ("swap", "both"):
        own = _reported(frames, rows, use)
        assert len(_rows_in(own, HOLE)) == 0
        assert not np.any(own[:, FLAG_COLUMN] == 1)
        assert np.array_equal(own[:, :2], rows[np.lexsort((rows[:, 1], rows[:, 0]))][:, :2])
    # the linker's colour alone leaves the fill's rule off: filled as without colour
    assert np.array_equal(_reported(frames, rows, "link"), plain)
    # and the same as the video's frames give the pass (stop 73): no second decode needed
    assert np.array_equal(_reported(frames, rows, "both"), smooth_tracks(rows, frames=frames))


def test_the_same_walker_across_an_occlusion_is_still_filled() -> None:
    frames, truth = _walkers()
    rows = truth[~np.isin(truth[:, 0], list(HOLE))]  # both hidden, ids kept
    own = _reported(frames, rows, "both")
    assert np.array_equal(own, _reported(frames, rows, None))
    assert len(_rows_in(own, HOLE)) == 2 * len(HOLE)


def _crossing_lanes(after: tuple[int, int, int], gap: range) -> tuple[list, np.ndarray]:
    """A red walker on the top lane, unseen from ``gap[0]`` on; a walker of colour `after`
    on the same path after `gap` (the same red one again, or a blue one); a red and a blue
    walker on two other lanes, walking the other way all along. BGR frames and true rows."""
    rng = np.random.default_rng(0)
    floor = rng.integers(90, 150, (200, 320, 1), dtype=np.uint8).repeat(3, axis=2)
    frames, rows = [], []
    for f in range(1, 31):
        image = floor.copy()
        walkers = [(3, RED, 280 - 5 * f, 150), (4, BLUE, 280 - 5 * f, 95)]
        if f < gap[0]:
            walkers.append((1, RED, 20 + 6 * f, 30))
        if f > gap[-1]:
            walkers.append((2, after, 20 + 6 * f, 30))
        for tid, colour, x, y in walkers:
            image[y : y + 30, x : x + 20] = colour
            rows.append([f, tid, x, y, 20, 30])
        frames.append(image)
    return frames, np.array(rows, dtype=np.float64)


def _finalized(frames: list, truth: np.ndarray, colour: str | None) -> np.ndarray:
    tracker = pftrack.Tracker.from_config(seed=0, colour=colour)
    for f, frame in enumerate(frames, start=1):
        b = truth[truth[:, 0] == f, 2:6]
        tracker.update(
            np.column_stack([b[:, :2], b[:, :2] + b[:, 2:], np.full(len(b), 0.95)]), frame
        )
    return tracker.finalize()


@pytest.mark.parametrize("gap", [range(11, 14), range(11, 16)], ids=["tracker", "linker"])
def test_the_trackers_hand_over_between_two_colours_is_left(gap: range) -> None:
    """The tracker itself hands the red walker's id to the blue one that appears on its path
    (3 frames unseen: the association; 5: a new id the offline linker joins). Without colour
    the pass fills the hole between them; with the tracker's histograms (the swap rule) it is
    left: the red side looks like the other red walker, the blue side like the blue one."""
    frames, truth = _crossing_lanes(BLUE, gap)
    plain = _finalized(frames, truth, None)
    top = plain[plain[:, 3] < 60]  # the top lane's rows: one id across the hole
    assert len(np.unique(top[:, 1])) == 1
    assert (plain[:, FLAG_COLUMN] == 1).sum() == len(gap)
    for use in ("swap", "both"):
        own = _finalized(frames, truth, use)
        assert not np.any(own[:, FLAG_COLUMN] == 1)
        assert len(own) == len(plain) - len(gap)
        assert not len(_rows_in(own[own[:, 3] < 60], gap))


def test_the_trackers_same_walker_across_an_occlusion_is_still_filled() -> None:
    frames, truth = _crossing_lanes(RED, range(11, 14))
    plain = _finalized(frames, truth, None)
    assert (plain[:, FLAG_COLUMN] == 1).sum() == 3
    for use in ("swap", "both"):
        assert np.array_equal(_finalized(frames, truth, use), plain)


def test_row_colours_answer_each_rows_histogram_and_zeros_elsewhere() -> None:
    """RowColours answers frame_histograms' question from the rows' histograms: a row's box
    (its own or its measured one) gets its histogram, any other box zeros (not judged)."""
    frames, truth = _walkers(6)
    hists = np.array([_colour(frames[int(r[0]) - 1], r[2:6]) for r in truth])
    measured = truth[:, 2:6] + 1.0
    stored = RowColours(truth, hists, measured)
    boxes = {2: truth[truth[:, 0] == 3, 2:6], 4: measured[truth[:, 0] == 5]}
    got = frame_histograms(boxes, stored)
    assert np.array_equal(got[2], hists[truth[:, 0] == 3])
    assert np.array_equal(got[4], hists[truth[:, 0] == 5])
    assert np.array_equal(frame_histograms(boxes, frames)[2], got[2])  # the frames' own bins
    other = frame_histograms({2: np.array([[0.0, 0.0, 5.0, 5.0]]), 40: truth[:1, 2:6]}, stored)
    assert not other[2].any() and not other[40].any()


def _tracked(colour: str | None, n_frames: int = 24) -> tuple[pftrack.Tracker, list, np.ndarray]:
    frames, truth = _walkers(n_frames)
    tracker = pftrack.Tracker.from_config(seed=0, colour=colour)
    for f, frame in enumerate(frames, start=1):
        b = truth[truth[:, 0] == f, 2:6]
        dets = np.column_stack([b[:, :2], b[:, :2] + b[:, 2:], np.full(len(b), 0.95)])
        tracker.update(dets, frame)
    return tracker, frames, truth


def test_the_histograms_kept_are_those_the_association_used() -> None:
    """Each row with a detection keeps the histogram of its detection box on its frame: a
    NumPy recomputation (tests/reference/kernels.py) of the full-frame bins gives the same."""
    tracker, frames, _ = _tracked("both")
    rows, boxes, has = tracker._writer.rows.arrays()
    hists = tracker._writer.rows.colours()
    assert hists is not None and hists.shape == (len(rows), 110)
    assert has.sum() > 20
    for k in np.flatnonzero(has)[:: max(1, int(has.sum()) // 8)].tolist():
        frame = frames[int(rows[k, 0]) - 1]
        want = ref.box_histograms(ref.hsv_bins(frame), 110, _cxcywh(boxes[k]))[0]
        np.testing.assert_allclose(hists[k], want, rtol=0, atol=1e-12)
        assert np.array_equal(hists[k], _colour(frame, boxes[k]))  # the core's bits


def test_off_keeps_nothing_and_finalize_is_unchanged_without_a_swap() -> None:
    off, _, _ = _tracked(None)
    assert off._writer.rows.colours() is None
    on, _, _ = _tracked("both")
    assert np.array_equal(on.finalize(), off.finalize())


def test_reset_clears_and_a_pickled_tracker_goes_on_alike() -> None:
    tracker, frames, truth = _tracked("both", 12)
    copy = pickle.loads(pickle.dumps(tracker))
    for t in (tracker, copy):
        for f in range(13, 25):
            b = truth[truth[:, 0] == f, 2:6] if f <= len(truth) // 2 else np.zeros((0, 4))
            dets = np.column_stack([b[:, :2], b[:, :2] + b[:, 2:], np.full(len(b), 0.95)])
            t.update(dets, frames[min(f, len(frames)) - 1])
    assert np.array_equal(copy._writer.rows.colours(), tracker._writer.rows.colours())
    assert np.array_equal(copy.finalize(), tracker.finalize())
    tracker.reset()
    assert tracker._writer.rows.colours() is None and len(tracker._writer.rows) == 0


def test_bad_histograms_and_options_are_refused_in_one_line() -> None:
    frames, truth = _walkers(6)
    h = np.full((len(truth), 110), 1 / 110)
    with pytest.raises(ValueError, match=r"histograms has shape \(3, 110\)"):
        smooth_tracks(truth, histograms=h[:3])
    with pytest.raises(ValueError, match="finite and >= 0"):
        smooth_tracks(truth, histograms=-h)
    with pytest.raises(ValueError, match="frames or histograms, not both"):
        smooth_tracks(truth, histograms=h, frames=frames)
    with pytest.raises(ValueError, match="colour is 'all'"):
        smooth_tracks(truth, histograms=h, colour="all")
    with pytest.raises(ValueError, match="colour is 'red'"):
        TrackWriter(colour="red")
    with pytest.raises(TypeError, match="colour must be"):
        TrackWriter(colour=1)  # type: ignore[arg-type]


def test_the_default_keeps_no_colour_and_an_online_tracker_none() -> None:
    tracker = pftrack.Tracker()
    assert tracker._writer.colour is None and not tracker._tracker.keep_colour
    assert pftrack.Tracker.from_config()._writer.colour is None
    online = pftrack.Tracker(record=False, colour="swap")
    assert not online._tracker.keep_colour  # nothing kept, nothing stored
    kept = pftrack.Tracker(colour="swap")
    assert kept._writer.colour == "swap" and kept._tracker.keep_colour
    with pytest.raises(ValueError, match="colour is 'red'"):
        pftrack.Tracker(colour="red")


def test_rows_keep_each_rows_histogram_across_blocks() -> None:
    """The writer's store: rows before the first histogram, rows without one, and rows kept
    without colours all read back as zeros; the others as given, across block boundaries."""
    from pftrack.tracking.writer import _Rows

    class Small(_Rows):
        BLOCK = 4

    rng = np.random.default_rng(3)
    store, want = Small(), []
    for n in range(11):
        k = n % 3 + 1
        rows = [[float(n + 1), float(j + 1), 0, 0, 1, 1, 1, -1, -1, -1] for j in range(k)]
        if n < 2:
            store.extend(rows, [None] * k)  # before any colour: zeros
            want += [np.zeros(5)] * k
            continue
        cols: list[np.ndarray | None] = [rng.random(5) for _ in range(k)]
        if n % 4 == 0:
            cols[0] = None
        if n == 7:
            store.extend(rows, [None] * k)  # kept without colours: zeros
            want += [np.zeros(5)] * k
            continue
        store.extend(rows, [None] * k, cols)
        want += [np.zeros(5) if c is None else c for c in cols]
    got = store.colours()
    assert got is not None and np.array_equal(got, np.array(want))
    assert len(got) == len(store) == len(store.arrays()[0])
    assert _Rows().colours() is None
