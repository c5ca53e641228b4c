"""The offline pass cuts a track where a detection re-finds it after a long coast.

``split_refound`` against a row-by-row reference, and the effect the cut is for: a particle
filter that coasted onto another person gives that person's detections to the wrong id; cut
and relinked, each piece joins the track its motion continues.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pftrack
from pftrack.tracking import LifecycleConfig, TrackerConfig, smooth_tracks
from pftrack.tracking.offline import split_refound


def reference(rows, observed, z, k):
    """Row by row: a new id after every run of >= k unobserved rows that a detection ends."""
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    a, obs, z = rows[order].copy(), observed[order], z[order]
    keep = np.ones(len(a), bool)
    next_id = float(a[:, 1].max()) + 1 if len(a) else 0.0
    i = 0
    while i < len(a):
        j = i
        while j < len(a) and a[j, 1] == a[i, 1]:
            j += 1
        cur, run, seen = a[i, 1], 0, False
        for r in range(i, j):
            if obs[r]:
                if seen and run >= k:
                    keep[r - run : r] = False
                    cur, next_id = next_id, next_id + 1
                seen, run = True, 0
            else:
                run += 1
            a[r, 1] = cur
        i = j
    return a[keep], obs[keep], z[keep]


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(st.integers(1, 4), st.booleans()), min_size=0, max_size=60),
    st.integers(1, 4),
    st.randoms(use_true_random=False),
)
def test_split_refound_matches_the_row_by_row_reference(cells, k, rnd):
    frames: dict[int, int] = {}
    rows, obs = [], []
    for tid, o in cells:
        frames[tid] = frames.get(tid, 0) + 1 + (rnd.random() < 0.2)  # holes in frames too
        rows.append([frames[tid], tid, 1, 2, 3, 4, 1, -1, -1, -1])
        obs.append(o)
    a = np.array(rows, float).reshape(-1, 10)
    o = np.array(obs, bool)
    perm = np.array(rnd.sample(range(len(a)), len(a)), int)
    a, o = a[perm], o[perm]
    z = np.arange(4 * len(a), dtype=float).reshape(-1, 4)
    got = split_refound(a, o, z, k)
    want = reference(a, o, z, k)
    for g, w in zip(got, want, strict=True):
        assert np.array_equal(g, w)


def test_split_refound_cuts_after_the_coast_only():
    f = np.arange(1, 21, dtype=float)
    rows = np.zeros((20, 10))
    rows[:, 0], rows[:, 1] = f, 7
    obs = np.ones(20, bool)
    obs[8:14] = False  # 6 coasted frames, then a detection
    z = np.zeros((20, 4))
    a, o, _ = split_refound(rows, obs, z, 6)
    assert a[:, 0].tolist() == [*range(1, 9), *range(15, 21)]
    assert set(a[a[:, 0] <= 8, 1]) == {7} and set(a[a[:, 0] >= 15, 1]) == {8}
    assert o.all()
    a, o, _ = split_refound(rows, obs, z, 7)  # a shorter coast is kept whole
    assert np.array_equal(a, rows) and np.array_equal(o, obs)


@pytest.mark.parametrize(("k", "error"), [(0, ValueError), (-2, ValueError), (1.5, TypeError),
                                          (True, TypeError)])  # fmt: skip
def test_split_refound_bad_count(k, error):
    with pytest.raises(error, match="min_unobserved"):
        split_refound(np.zeros((0, 10)), np.zeros(0, bool), np.zeros((0, 4)), k)


@pytest.mark.parametrize("value", [0, -1, 2.0, True, "7"])
def test_relink_coast_is_checked(value):
    # LifecycleConfig: a wrong type is a TypeError (was ValueError), an int < 1 a ValueError
    error = ValueError if isinstance(value, int) and not isinstance(value, bool) else TypeError
    with pytest.raises(error, match="relink_coast"):
        LifecycleConfig(relink_coast=value)
    rows, obs = walker_rows(1, range(1, 5), 100, 2.0)
    with pytest.raises(ValueError, match="smooth_tracks: relink_coast"):
        smooth_tracks(rows, obs, relink_coast=value)
    assert LifecycleConfig(relink_coast=None).relink_coast is None


def walker_rows(tid, frames, x0, vx, observed=True):
    f = np.asarray(frames, float)
    r = np.zeros((len(f), 10))
    r[:, 0], r[:, 1] = f, tid
    r[:, 2], r[:, 3], r[:, 4], r[:, 5], r[:, 6] = x0 + vx * f, 100, 20, 50, 1
    r[:, 7:] = -1
    return r, np.full(len(f), observed)


def hijack():
    """Two walkers; id 1 coasts frames 21-28 and re-finds walker B, whose id 2 ended at 20.

    Walker A (x = 100 + 2 f) is re-detected from frame 30 as id 3; walker B
    (x = 400 - 2 f) keeps its motion, so after the cut id 1's re-found piece continues id 2.
    """
    parts = [
        walker_rows(1, range(1, 21), 100, 2.0),  # A, detected
        walker_rows(1, range(21, 29), 100, 2.0, observed=False),  # coasting
        walker_rows(1, range(29, 50), 400, -2.0),  # B's detections under A's id
        walker_rows(2, range(1, 21), 400, -2.0),  # B, detected, then ended
        walker_rows(3, range(30, 50), 100, 2.0),  # A re-born
    ]
    rows = np.vstack([p[0] for p in parts])
    obs = np.concatenate([p[1] for p in parts])
    return rows, obs


def ids_by_walker(out):
    x_at = {int(f): {} for f in np.unique(out[:, 0])}
    for r in out:
        x_at[int(r[0])][int(r[1])] = r[2]
    a = {t for f, d in x_at.items() for t, x in d.items() if abs(x - (100 + 2 * f)) < 5}
    b = {t for f, d in x_at.items() for t, x in d.items() if abs(x - (400 - 2 * f)) < 5}
    return a, b


def test_a_hijacked_track_is_cut_and_relinked():
    rows, obs = hijack()
    before = smooth_tracks(rows, obs)
    a, b = ids_by_walker(before)
    assert len(a) == 2 and len(b) == 2  # without the cut: A has ids {1, 3}, B {1, 2}
    after = smooth_tracks(rows, obs, relink_coast=6)
    a, b = ids_by_walker(after)
    assert len(a) == 1 and len(b) == 1 and a != b  # one id per walker
    same = smooth_tracks(rows, obs, relink_coast=9)  # a shorter coast than 9: no cut
    assert np.array_equal(same, before)


def coasting_run(config: TrackerConfig) -> np.ndarray:
    """One walker on black 640x480 frames, undetected for frames 16-22 (the track coasts)."""
    tracker = pftrack.Tracker.from_config(config, seed=0)
    frame = np.zeros((480, 640, 3), np.uint8)
    for f in range(1, 41):
        x = 100 + 3 * f
        dets = np.zeros((0, 5)) if 16 <= f <= 22 else np.array([[x, 150, x + 40, 250, 1.0]])
        tracker.update(dets, frame)
    return tracker.finalize()


@pytest.mark.filterwarnings("ignore:frame 1 is blank")  # black frames: boxes only
def test_the_tracker_cuts_coasts_before_linking(monkeypatch):
    from pftrack.tracking import offline

    calls = []

    def spy(rows, observed, z, k):
        calls.append((k, int((~observed).sum())))
        return split_refound(rows, observed, z, k)

    monkeypatch.setattr(offline, "split_refound", spy)
    on = coasting_run(TrackerConfig())
    assert calls == [(7, 7)]  # 7 coasted rows, cut at the 7-frame default
    assert len(np.unique(on[:, 1])) == 1  # the linker joined the two pieces back
    assert sorted(on[:, 0].astype(int)) == list(range(1, 41))  # the hole filled again
    calls.clear()
    off = coasting_run(TrackerConfig(lifecycle=LifecycleConfig(relink_coast=None)))
    assert calls == [] and len(np.unique(off[:, 1])) == 1
    assert pftrack.Tracker().config.lifecycle.relink_coast == 7
    assert pftrack.Tracker(frame_rate=10.0).config.lifecycle.relink_coast == 7  # frames


def test_split_refound_refuses_ids_it_cannot_extend():
    from pftrack.recovery.linking import MAX_ID

    rows, obs = walker_rows(MAX_ID, range(1, 12), 100, 2.0)
    obs[3:9] = False  # one cut would need the id MAX_ID + 1
    with pytest.raises(ValueError, match="no room"):
        split_refound(rows, obs, np.zeros((len(rows), 4)), 6)


@pytest.mark.parametrize(
    ("owner", "field"),
    [("lifecycle", "max_coast"), ("lifecycle", "min_hits"), ("camera", "on_frames")],
)
def test_frame_counts_refuse_a_bool(owner, field):
    from pftrack.tracking import CameraConfig

    cls = LifecycleConfig if owner == "lifecycle" else CameraConfig
    with pytest.raises(TypeError, match=rf"{field} must be an integer .*, got bool True"):
        cls(**{field: True})
