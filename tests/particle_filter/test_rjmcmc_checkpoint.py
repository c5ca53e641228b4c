"""The joint sampler's state can be saved and restored (``RJMCMCTracker.restore``, pickle).

Until 5 December 2026 the chain lived in the C++ core with no way out: a pickle or deepcopy of
an RJMCMCFilter (or of a ``Tracker(sampler="rjmcmc")`` after its first frame) was refused.
"""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

from pftrack import _core
from pftrack.particle_filter.rjmcmc import RJMCMCConfig, RJMCMCFilter
from tests.particle_filter.test_rjmcmc import BLOBS, PARAMS, boxes, scene


def frames(n):
    for step in range(n):
        moved = [((cx + step, cy), col) for (cx, cy), col in BLOBS]
        frame, mask = scene(100 + step, moved)
        yield _core.hsv_bins(frame, mask), mask, boxes(moved)


@pytest.mark.parametrize("how", ["pickle", "deepcopy"])
def test_a_copied_filter_goes_on_as_the_original(how):
    a = RJMCMCFilter(RJMCMCConfig(**PARAMS), rng=7)
    seq = list(frames(8))
    for f in seq[:4]:
        a.step(*f)
    b = pickle.loads(pickle.dumps(a)) if how == "pickle" else copy.deepcopy(a)
    for f in seq[4:]:
        x, y = a.step(*f), b.step(*f)
        np.testing.assert_array_equal(a.last["estimates"], b.last["estimates"])
        np.testing.assert_array_equal(a.last["map"], b.last["map"])
        assert a.last["acceptance"] == b.last["acceptance"]
        assert [t.id for t in x] == [t.id for t in y]
    assert b._core.next_id == a._core.next_id > 0


def test_restore_takes_the_state_it_gave():
    a, b = _core.RJMCMCTracker(**PARAMS), _core.RJMCMCTracker(**PARAMS)
    seq = list(frames(3))
    for k, f in enumerate(seq[:2]):
        a.step(*f, seed=4, step=k)
    b.restore(a.tracks, a.next_id)
    ra, rb = (t.step(*seq[2], seed=4, step=2) for t in (a, b))
    np.testing.assert_array_equal(ra["estimates"], rb["estimates"])


def _state():
    t = _core.RJMCMCTracker(**PARAMS)
    for k, f in enumerate(frames(2)):
        t.step(*f, seed=4, step=k)
    return t, t.tracks, t.next_id


def _with(tracks, k, **changes):
    out = [dict(d) for d in tracks]
    out[k].update(changes)
    return out


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        (lambda ts, n: (ts, -1), ValueError, r"next_id is -1, expected >= 0"),
        (lambda ts, n: (_with(ts, 0, id=n), n), ValueError, r"tracks\[0\]\.id is \d+, expected"),
        (lambda ts, n: (_with(ts, 1, id=ts[0]["id"]), n), ValueError, "is given twice"),
        (lambda ts, n: (_with(ts, 0, w0=0.0), n), ValueError, "w0 and h0 must be finite and > 0"),
        (lambda ts, n: (_with(ts, 0, h0=np.nan), n), ValueError, "w0 and h0 must be finite"),
        (lambda ts, n: (_with(ts, 0, ref=np.zeros(110)), n), ValueError, r"ref must hold"),
        (lambda ts, n: (_with(ts, 1, ref=np.ones(7)), n), ValueError, r"as long as tracks\[0\]"),
        (lambda ts, n: (_with(ts, 0, parents=np.zeros((3, 5))), n), ValueError, r"\(N, 6\)"),
        (lambda ts, n: (_with(ts, 0, parents=np.zeros((0, 6))), n), ValueError, r"\(N, 6\)"),
        (lambda ts, n: (_with(ts, 0, parents=np.full((2, 6), np.inf)), n), ValueError, "finite"),
        (lambda ts, n: (_with(ts, 0, existence=0.0), n), ValueError, r"existence is 0"),
        (lambda ts, n: (_with(ts, 0, existence=1.5), n), ValueError, r"existence is 1.5"),
        (lambda ts, n: ([*ts, 3], n), ValueError, "tracks must be dicts"),
        (lambda ts, n: ([{"id": 0}], n), ValueError, "a track has no 'w0'"),
        (lambda ts, n: (_with(ts, 0, w0="wide"), n), TypeError, "not numbers"),
    ],
)
def test_restore_refuses_a_bad_state_and_keeps_its_own(change, error, message):
    t, tracks, next_id = _state()
    assert len(tracks) >= 2
    with pytest.raises(error, match=message):
        t.restore(*change(tracks, next_id))
    assert t.next_id == next_id
    for p, q in zip(tracks, t.tracks, strict=True):
        np.testing.assert_array_equal(p["parents"], q["parents"])


def test_the_core_alone_still_has_no_pickled_form():
    with pytest.raises(TypeError, match="RJMCMCTracker"):
        pickle.dumps(_core.RJMCMCTracker(**PARAMS))
