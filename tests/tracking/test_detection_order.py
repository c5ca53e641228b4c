"""A frame's detections in another order give the same tracks (ids, boxes and rows)."""

from __future__ import annotations

import numpy as np
import pytest

import pftrack
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_busy_scene
from pftrack.tracking.tracker import canonical_order

# the 'present' scene unprimed: people over a third of the frame while the background learnt
pytestmark = pytest.mark.filterwarnings("ignore:noisy or changing video:UserWarning")


@pytest.fixture(scope="module")
def scene():
    return make_busy_scene("present", n_frames=60, rng=3)


def truth_dets(scene, tied: bool, classes: bool) -> list[np.ndarray]:
    """Per frame ``x1, y1, x2, y2, conf(, cls)`` from the truth, in the truth's order."""
    g = np.random.default_rng(0)
    by_frame = group_by_frame(scene.truth)
    out = []
    for f in range(1, len(scene.frames) + 1):
        r = by_frame.get(f, np.zeros((0, 10)))
        conf = np.full(len(r), 0.9) if tied else g.uniform(0.5, 1.0, len(r))
        cols = [r[:, 2:4], r[:, 2:4] + r[:, 4:6], conf]
        if classes:
            cols.append(r[:, 1] % 2)  # two classes
        out.append(np.column_stack(cols))
    return out


def run(scene, dets):
    tracker = pftrack.Tracker(seed=0)
    outs = [tracker.update(d, f) for d, f in zip(dets, scene.frames, strict=True)]
    return outs, tracker.finalize()


@pytest.mark.parametrize(("tied", "classes"), [(False, False), (True, False), (False, True)])
def test_shuffled_rows_give_the_same_tracks(scene, tied: bool, classes: bool) -> None:
    dets = truth_dets(scene, tied, classes)
    g = np.random.default_rng(7)
    perms = [g.permutation(len(d)) for d in dets]
    assert any((p != np.arange(len(p))).any() for p in perms)
    outs_a, rows_a = run(scene, dets)
    outs_b, rows_b = run(scene, [d[p] for d, p in zip(dets, perms, strict=True)])
    np.testing.assert_array_equal(rows_a, rows_b)
    assert len(rows_a) > 200
    for a, b, p in zip(outs_a, outs_b, perms, strict=True):
        np.testing.assert_array_equal(a[:, :7], b[:, :7])
        # det_ind names the caller's row: the same detection under its shuffled index
        named = np.where(b[:, 7] >= 0, p[b[:, 7].astype(int).clip(0)], -1)
        np.testing.assert_array_equal(a[:, 7], named)


def test_canonical_order_is_score_then_box_then_class() -> None:
    g = np.random.default_rng(1)
    n = 40
    boxes = g.integers(0, 3, size=(n, 4)).astype(float)  # many ties on every key
    scores = g.choice([0.5, 0.9], size=n)
    labels = g.integers(0, 2, size=n)
    order = canonical_order(boxes, scores, labels)
    keys = [(-scores[i], *boxes[i], labels[i], i) for i in range(n)]  # i: stable among equals
    assert order.tolist() == [k[-1] for k in sorted(keys)]
