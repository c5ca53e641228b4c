"""``experiments.perturbed_detections``: each copy changes what its docstring says, seeded."""

from __future__ import annotations

import numpy as np
import pytest

from experiments import perturbed_detections as ex
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def base() -> ex.Copy:
    """A synthetic scene as a copy: its truth, and boxes made from the truth (scores 0.5-1)."""
    scene = make_scene(n_frames=120, n_walkers=6, rng=3)
    rng = np.random.default_rng(0)
    by_frame = group_by_frame(scene.truth)
    dets = {
        f: np.column_stack([r[:, 2:6], rng.uniform(0.5, 1.0, len(r))]) for f, r in by_frame.items()
    }
    h, w = scene.frames[0].shape[:2]
    # truth in pixels of twice the frame's size (scale 0.5), as PETS09's are at 0.625
    gt = scene.truth.copy()
    gt[:, 2:6] *= 2.0
    return ex.Copy(list(scene.frames), dets, gt, 0.5, 10.0, (w, h))


def _count(dets: ex.Dets) -> int:
    return sum(len(d) for d in dets.values())


def test_copies_are_seeded(base: ex.Copy) -> None:
    for kind in ("miss-random", "miss-bursts", "jitter", "false-low"):
        a = ex.make_copy(base, kind, np.random.default_rng([0, 1, 2]))
        b = ex.make_copy(base, kind, np.random.default_rng([0, 1, 2]))
        c = ex.make_copy(base, kind, np.random.default_rng([0, 1, 3]))
        assert all(np.array_equal(a.dets[f], b.dets[f]) for f in base.dets)
        assert not all(np.array_equal(a.dets[f], c.dets[f]) for f in base.dets)


def test_misses_leave_out_a_fifth_and_bursts_come_in_runs(base: ex.Copy) -> None:
    n = _count(base.dets)
    rnd = ex.make_copy(base, "miss-random", np.random.default_rng(1))
    assert 0.15 < 1 - _count(rnd.dets) / n < 0.25
    runs = []
    left = 0
    for seed in range(5):
        burst = ex.make_copy(base, "miss-bursts", np.random.default_rng(seed))
        left += _count(burst.dets)
        ids = ex.truth_ids(base.dets, base.gt, base.scale)
        kept = ex.truth_ids(burst.dets, base.gt, base.scale)
        for k in np.unique(np.concatenate(list(ids.values()))):
            seen = [bool(np.any(kept[f] == k)) for f in sorted(ids) if np.any(ids[f] == k)]
            run = 0
            for s in seen + [True]:
                if not s:
                    run += 1
                elif run:
                    runs.append(run)
                    run = 0
    assert 0.12 < 1 - left / (5 * n) < 0.28
    assert np.mean(runs) > 3  # bursts of 5 frames on average; each on its own would give 1.25


def test_jitter_moves_boxes_by_about_five_percent(base: ex.Copy) -> None:
    j = ex.make_copy(base, "jitter", np.random.default_rng(0))
    a = np.concatenate([base.dets[f] for f in sorted(base.dets)])
    b = np.concatenate([j.dets[f] for f in sorted(base.dets)])
    np.testing.assert_array_equal(a[:, 4], b[:, 4])
    dx = (b[:, 0] + b[:, 2] / 2 - a[:, 0] - a[:, 2] / 2) / a[:, 2]
    dh = np.log(b[:, 3] / a[:, 3])
    assert 0.04 < dx.std() < 0.06
    assert 0.04 < dh.std() < 0.06


def test_false_boxes_add_a_tenth_scored_low(base: ex.Copy) -> None:
    f = ex.make_copy(base, "false-low", np.random.default_rng(0))
    every = np.concatenate(list(base.dets.values()))
    lo, hi = np.percentile(every[:, 4], [5, 50])
    added = np.concatenate([f.dets[k][len(base.dets[k]) :] for k in base.dets])
    assert 0.05 < len(added) / len(every) < 0.15
    assert np.all((added[:, 4] >= lo) & (added[:, 4] <= hi))
    w, h = base.size
    assert np.all(added[:, 0] >= 0) and np.all(added[:, 0] + added[:, 2] <= w + 1)


def test_rescored_keeps_the_ranking(base: ex.Copy) -> None:
    r = ex.make_copy(base, "rescored", np.random.default_rng(0))
    for f, d in base.dets.items():
        np.testing.assert_allclose(r.dets[f][:, 4], d[:, 4] ** 8)
        np.testing.assert_array_equal(r.dets[f][:, :4], d[:, :4])


def test_half_rate_keeps_odd_frames_renumbered(base: ex.Copy) -> None:
    h = ex.make_copy(base, "half-rate", np.random.default_rng(0))
    assert h.fps == base.fps / 2
    assert len(h.frames) == (len(base.frames) + 1) // 2
    frames = list(h.frames)
    np.testing.assert_array_equal(frames[1], base.frames[2])  # frame 2 is the old frame 3
    np.testing.assert_array_equal(h.dets[2], base.dets[3])
    old = base.gt[base.gt[:, 0] == 3]
    new = h.gt[h.gt[:, 0] == 2]
    np.testing.assert_array_equal(old[:, 1:], new[:, 1:])


def test_walking_shifts_frames_boxes_and_truth_alike(base: ex.Copy) -> None:
    wk = ex.make_copy(base, "walking", np.random.default_rng(0))
    t = 17  # near a quarter of the 60-frame sway, and off the 10-frame bob's zeros
    dx, dy = ex.walking_shift(t, base.fps, base.size)
    assert abs(dx) > 0.07 * base.size[0]
    gt0, gt1 = base.gt[base.gt[:, 0] == t], wk.gt[wk.gt[:, 0] == t]
    np.testing.assert_allclose(gt1[:, 2] - gt0[:, 2], dx / base.scale, atol=1e-9)
    np.testing.assert_allclose(gt1[:, 3] - gt0[:, 3], dy / base.scale, atol=1e-9)
    assert abs(dy) > 0.005 * base.size[1]
    # a box wholly in view moves by the same shift in the frame's pixels
    d0, d1 = base.dets[t], wk.dets[t]
    w, h = base.size
    inside = (
        (d0[:, 0] + dx >= 0)
        & (d0[:, 1] + dy >= 0)
        & (d0[:, 0] + d0[:, 2] + dx <= w)
        & (d0[:, 1] + d0[:, 3] + dy <= h)
    )
    assert inside.any()
    moved = d0[inside].copy()
    moved[:, 0] += dx
    moved[:, 1] += dy
    for row in moved:
        assert np.any(np.all(np.isclose(d1, row), axis=1))
    # the frame moves with them: its content shifted by the rounded shift
    frame = next(f for i, f in enumerate(wk.frames, start=1) if i == t)
    x, y = round(dx), round(dy)
    src = base.frames[t - 1]
    a = src[40 : h - 40, 80 : w - 80].astype(int)
    b = frame[40 + y : h - 40 + y, 80 + x : w - 80 + x].astype(int)
    assert np.abs(a - b).mean() < 8
