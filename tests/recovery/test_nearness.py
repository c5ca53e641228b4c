"""``auto``'s nearness resampling: a bucket whose real gaps are faster than its validation gaps.

Where the file holds few places as fast as the gaps to fill, those are used up and the bucket's
validation fills with slower ones (KITTI-17's mask ``894,108``). A one-sided rank test then
weights the validation gaps nearest the real ones (``calibrate._matched_weights``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pftrack.recovery.calibrate import calibrate


def _reference_z(x: np.ndarray, y: np.ndarray) -> float:
    """Mann-Whitney z from its definition: pairs counted one by one, tie-corrected variance."""
    u = sum(1.0 if a > b else 0.5 if a == b else 0.0 for a in x for b in y)
    n1, n2 = len(x), len(y)
    n = n1 + n2
    _, sizes = np.unique(np.concatenate([x, y]), return_counts=True)
    ties = sum(int(t) ** 3 - int(t) for t in sizes)
    return (u - n1 * n2 / 2) / math.sqrt(n1 * n2 / 12 * ((n + 1) - ties / (n * (n - 1))))


@pytest.mark.parametrize("decimals", [None, 1, 0])
def test_rank_z_is_the_tie_corrected_normal_approximation(decimals: int | None) -> None:
    """Equal to the pair count's z and to SciPy's asymptotic test, ties (rounded values) or not."""
    from scipy import stats

    from pftrack.recovery.calibrate import _rank_z

    rng = np.random.default_rng(5)
    for _ in range(20):
        x = rng.normal(0.4, 1.0, int(rng.integers(3, 30)))
        y = rng.normal(0.0, 1.0, int(rng.integers(5, 200)))
        if decimals is not None:
            x, y = np.round(x, decimals), np.round(y, decimals)
        z = _rank_z(x, y)
        assert z == pytest.approx(_reference_z(x, y), rel=1e-12, abs=1e-12)
        p = stats.mannwhitneyu(
            x, y, alternative="greater", method="asymptotic", use_continuity=False
        ).pvalue
        assert z == pytest.approx(stats.norm.isf(p), rel=1e-9, abs=1e-9)


def test_rank_z_counts_ties() -> None:
    """With many ties the corrected variance is smaller, so |z| is larger than without it."""
    from pftrack.recovery.calibrate import _rank_z

    x = np.array([2.0, 2.0, 2.0, 3.0, 3.0])
    y = np.array([1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0, 1.0])
    n1, n2 = len(x), len(y)
    u = 3 * 4 + 3 * 4 * 0.5 + 2 * 8  # x = 2 beats the four 1s, ties the four 2s; x = 3 beats all
    plain = (u - n1 * n2 / 2) / math.sqrt(n1 * n2 * (n1 + n2 + 1) / 12)
    assert _rank_z(x, y) > plain + 0.1
    assert _rank_z(x, y) == pytest.approx(_reference_z(x, y))


def test_rank_z_without_anything_to_rank_is_zero() -> None:
    from pftrack.recovery.calibrate import _rank_z

    assert _rank_z(np.ones(4), np.ones(9)) == 0.0
    assert _rank_z(np.zeros(0), np.ones(3)) == 0.0
    assert _rank_z(np.ones(3), np.zeros(0)) == 0.0


def _validation_gap(dist: float, length: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """An artificial gap ``(segment_a, segment_b, truth, run)``, end points `dist` px apart."""
    a = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    b = np.array([[length + 2.0, dist, 0.0], [length + 3.0, dist, 0.0]])
    truth = np.column_stack([np.arange(2.0, length + 2.0), np.zeros(length), np.zeros(length)])
    return a, b, truth, 0


def _bucket(rng: np.random.Generator, real_speed: float, n_real: int = 10):  # type: ignore[no-untyped-def]
    """90 validation gaps of 6 frames mostly 2-4 px a frame, 10 of 20 px, and the real gaps."""
    speeds = np.r_[rng.uniform(2.0, 4.0, 90), np.full(10, 20.0)]
    cut = [_validation_gap(7 * float(v), 6) for v in speeds]
    targets = [(6, 7 * real_speed + 0.1 * k, 3, 3) for k in range(n_real)]
    return cut, targets


def test_matched_weights_none_unless_the_real_gaps_are_faster() -> None:
    from pftrack.recovery.calibrate import _matched_weights

    rng = np.random.default_rng(0)
    for speed in (3.0, 2.0, 0.5):  # as fast as the validation gaps, or slower
        cut, targets = _bucket(rng, speed)
        assert _matched_weights(cut, targets) is None
    cut, _ = _bucket(rng, 20.0)
    assert _matched_weights(cut, []) is None
    assert _matched_weights([], [(6, 140.0, 3, 3)]) is None
    # unmatched targets (no end-point distance, -1) are never weighted
    assert _matched_weights(cut, [(6, -1.0, -1, -1)] * 5) is None


def test_matched_weights_go_to_the_validation_gaps_nearest_the_fast_real_gaps() -> None:
    from pftrack.recovery.calibrate import _matched_weights

    cut, targets = _bucket(np.random.default_rng(0), 20.0)
    w = _matched_weights(cut, targets)
    assert w is not None and w.shape == (100,)
    assert w.sum() == pytest.approx(1.0) and (w >= 0).all()
    # each real gap takes ceil(100 / 10) = 10 validation gaps: the ten of 20 px a frame
    np.testing.assert_allclose(w[90:], 0.1)
    assert w[:90].sum() == 0.0
    # fewer real gaps take more neighbours each: the ten fast ones and the fastest slow ones
    cut, targets = _bucket(np.random.default_rng(0), 20.0, n_real=4)
    w = _matched_weights(cut, targets)
    assert w is not None
    np.testing.assert_allclose(w[90:], 1 / 25)
    slow = np.array([np.hypot(*(b[0, 1:3] - a[-1, 1:3])) for a, b, _, _ in cut[:90]])
    assert np.flatnonzero(w[:90]).tolist() == sorted(np.argsort(slow)[-15:].tolist())
    # the same input, the same weights
    again = _matched_weights(cut, targets)
    assert again is not None
    np.testing.assert_array_equal(w, again)


def _fast_gaps_file(seed: int = 0) -> list[np.ndarray]:
    """40 slow random walkers (2 px steps) and 2 short tracks at 20 px a frame that weave.

    A random walk's best fill is the straight line between its ends; the weaving fast tracks
    want a path that follows their end velocities. The fast tracks hold 14 places for a gap
    of 6 frames with 3 points each side, so most of the validation gaps cut for fast real
    gaps come from the slow walkers.
    """
    rng = np.random.default_rng(seed)
    runs = []
    for i in range(40):
        t = np.arange(60.0)
        xy = np.cumsum(rng.normal(0.0, 2.0, (60, 2)), axis=0) + [100.0, 100.0 + 30 * i]
        runs.append(np.column_stack([t, xy]))
    for i in range(2):
        t = np.arange(18.0)
        phase = rng.uniform(0, 2 * np.pi)
        x = 2000 + 20 * t + rng.normal(0, 0.3, 18)
        y = 500 + 300 * i + 20 * np.sin(t / 3 + phase) + rng.normal(0, 0.3, 18)
        runs.append(np.column_stack([t, x, y]))
    return runs


def _weights(cal_bucket) -> dict[str, float]:  # type: ignore[no-untyped-def]
    return dict(cal_bucket.weights) if cal_bucket.weights else {cal_bucket.method: 1.0}


@pytest.mark.parametrize("seed", [0, 1])
def test_fast_real_gaps_validated_mostly_on_slow_places_choose_a_goal_directed_fill(
    seed: int,
) -> None:
    """30 real gaps of 6 frames at 20 px a frame: the bucket leaves the straight line.

    Unweighted, the validation gaps (mostly slow walkers) rate ``linear`` first and the
    bucket is filled with straight lines (the code before the nearness resampling did so);
    weighted by nearness to the real gaps, the fast places decide and a goal-directed method
    (``gdt-bi``, ``gdt-fixed`` or ``gdt-mix``) takes most of the weight.
    """
    runs = _fast_gaps_file()
    n = 30
    cal = calibrate(
        runs, [6] * n, spans=[140.0 + k for k in range(n)], contexts=[(3, 3)] * n, seed=seed
    )
    (bucket,) = cal.buckets
    assert bucket.n_validation >= 100 and bucket.replaced is None
    w = _weights(bucket)
    assert w.get("linear", 0.0) < 0.2
    assert sum(v for m, v in w.items() if m.startswith("gdt")) > 0.8
    # real gaps as fast as the walkers' (7 steps of 2 px per axis: about 7 px) keep the line
    slow = calibrate(runs, [6] * n, spans=[7.0] * n, contexts=[(3, 3)] * n, seed=seed)
    assert _weights(slow.buckets[0]).get("linear", 0.0) > 0.8


def test_nearness_resampling_is_deterministic() -> None:
    runs = _fast_gaps_file()
    kw = dict(spans=[140.0 + k for k in range(30)], contexts=[(3, 3)] * 30, seed=2)
    assert calibrate(runs, [6] * 30, **kw) == calibrate(runs, [6] * 30, **kw)  # type: ignore[arg-type]
