"""``_core.rts_gaps_batch`` (the ``rts`` baseline over many gaps) against its NumPy reference."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from pftrack import _core
from pftrack.recovery.baselines import rts_batch
from tests.reference.smoothing import rts_batch_numpy


def _pairs(seed: int, n: int = 80) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        na, nb = (int(v) for v in rng.integers(1, 45, 2))
        L = int(rng.integers(0, 40))
        f0 = int(rng.integers(1, 1000))
        fa, fb = np.arange(f0, f0 + na), np.arange(f0 + na + L, f0 + na + L + nb)
        a = np.column_stack([fa, np.cumsum(rng.normal(0, 3, (na, 2)), axis=0)])
        b = np.column_stack([fb, np.cumsum(rng.normal(0, 3, (nb, 2)), axis=0) + rng.normal(0, 9)])
        if na > 5:
            a = np.delete(a, int(rng.integers(1, na - 1)), axis=0)  # a hole inside a window
        if L == 0:  # no frame missing: B starts right after A
            b[:, 0] += 1
        out.append((a, b))
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(("q", "r", "history"), [(0.1, 1.0, 30), (2.0, 16.0, 5), (1e-4, 1e-2, 60)])
def test_equals_numpy_reference(seed: int, q: float, r: float, history: int) -> None:
    pairs = _pairs(seed)
    got = rts_batch(pairs, q, r, history)
    want = rts_batch_numpy(pairs, q, r, history)
    assert len(got) == len(want) == len(pairs)
    for (a, b), g, w in zip(pairs, got, want, strict=True):
        assert g.shape == w.shape == (int(b[0, 0] - a[-1, 0]) - 1, 2)
        np.testing.assert_allclose(g, w, rtol=1e-10, atol=1e-8)


def test_straight_line_is_recovered() -> None:
    """Up to the start prior (velocity 0, variance 100), which the first points outweigh."""
    t = np.arange(40.0)
    line = np.column_stack([t, 3.0 + 2.5 * t, -1.0 - 0.5 * t])
    (got,) = rts_batch([(line[:15], line[25:])], q=0.1, r=1.0)
    np.testing.assert_allclose(got, line[15:25, 1:], atol=1e-4)


def test_same_from_threads() -> None:
    """GIL released: four threads at once give the serial result."""
    pairs = _pairs(3, 200)
    want = np.vstack(rts_batch(pairs))
    with ThreadPoolExecutor(4) as pool:
        res = list(pool.map(lambda _: np.vstack(rts_batch(pairs)), range(4)))
    assert len(res) == 4
    for r in res:
        np.testing.assert_array_equal(r, want)


def _args() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pts = np.array([[1, 0, 0], [2, 1, 1], [5, 4, 4], [6, 5, 5]], dtype=np.float64)
    return pts, np.array([0, 4], np.int32), np.array([2], np.int32)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda p, o, n: (p[:, :2], o, n), "points cols"),
        (lambda p, o, n: (p, o[:1], n), "n_before size"),
        (lambda p, o, n: (p, np.array([0, 3], np.int32), n), r"offsets\[-1\]"),
        (lambda p, o, n: (p, np.array([1, 4], np.int32), n), r"offsets\[0\]"),
        (lambda p, o, n: (p, o, np.array([0], np.int32)), r"n_before\[0\] is 0"),
        (lambda p, o, n: (p, o, np.array([4], np.int32)), r"n_before\[0\] is 4"),
        (lambda p, o, n: (p[[0, 2, 1, 3]], o, n), "does not follow"),
        (lambda p, o, n: (p + [[0.5, 0, 0]], o, n), "not an integer"),
        (lambda p, o, n: (np.where(p == 4, np.nan, p), o, n), "non-finite"),
    ],
)
def test_bad_input_names_the_problem(change: object, match: str) -> None:
    p, o, n = change(*_args())  # type: ignore[operator]
    with pytest.raises(ValueError, match=match):
        _core.rts_gaps_batch(np.ascontiguousarray(p), o, n, 0.1, 1.0, 100.0)


@pytest.mark.parametrize(("q", "r", "v0"), [(0.0, 1.0, 1.0), (0.1, -1.0, 1.0), (0.1, 1.0, np.inf)])
def test_bad_noise_is_refused(q: float, r: float, v0: float) -> None:
    with pytest.raises(ValueError, match="rts_gaps_batch: (q|r|v0) is"):
        _core.rts_gaps_batch(*_args(), q, r, v0)


def test_huge_window_is_refused_before_allocation() -> None:
    pts = np.array([[1, 0, 0], [2, 0, 0], [1e12, 0, 0]], dtype=np.float64)
    with pytest.raises(ValueError, match="limit"):
        _core.rts_gaps_batch(pts, np.array([0, 3], np.int32), np.array([2], np.int32), 0.1, 1, 1)


def test_no_gap() -> None:
    out = _core.rts_gaps_batch(np.zeros((0, 3)), np.zeros(1, np.int32), np.zeros(0, np.int32),
                               0.1, 1.0, 100.0)  # fmt: skip
    assert out.shape == (0, 2)
