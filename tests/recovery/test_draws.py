"""The calibration's draws in bulk: the same integers and generator state as one call each.

``calibrate._artificial_gaps`` draws the places of a batch of attempts in one
``Generator.integers`` call over an array of bounds (each attempt's bound repeated
``MATCH_DRAWS`` times), where it made one call of ``MATCH_DRAWS`` values per attempt. That is
the documented random stream only because NumPy draws an array of bounds element by element as
it draws one bound's `size` values: the tests below hold NumPy to it, over many bounds and seeds,
and the artificial gaps to the one-attempt-at-a-time reference (tests/reference/calibrate.py),
regions included.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from pftrack._typing import F64
from pftrack.recovery import calibrate
from pftrack.recovery.calibrate import MATCH_DRAWS, _artificial_gaps, _flat, _region_blocks
from tests.reference.calibrate import artificial_gaps

# Lemire's method on 32 bits up to 2**32 (1: nothing drawn; near 2**31 and 2**32 - 1: many
# rejections; 2**32: every 32-bit value), on 64 bits past it
EDGES = (1, 2, 3, 7, 16, 1000, 2**31 - 1, 2**31 + 1, 3 * 2**30, 2**32 - 1, 2**32, 2**32 + 1)


def _bounds(rng: np.random.Generator, k: int) -> list[int]:
    top = int(rng.choice([10, 1000, 2**20, 2**31 + 7, 2**32, 2**33, 2**62]))
    out = [int(v) for v in rng.integers(1, top, size=k, endpoint=True)]
    out += [int(v) for v in rng.choice(EDGES, size=k // 3)]
    return [out[i] for i in rng.permutation(len(out))]


@pytest.mark.parametrize("seed", range(40))
def test_an_array_of_bounds_draws_as_one_call_per_bound(seed: int) -> None:
    """``integers(np.repeat(bounds, m))`` gives each bound's ``integers(b, size=m)`` in turn,
    and leaves the generator as they do (PCG64's buffered 32-bit half included: an odd number
    of 32-bit draws before, or between)."""
    pick = np.random.default_rng([seed, 67])
    bounds = _bounds(pick, int(pick.integers(1, 60)))
    m = int(pick.choice([1, 3, MATCH_DRAWS]))
    one, bulk = np.random.default_rng(seed), np.random.default_rng(seed)
    if seed % 2:  # a 32-bit half left in the generator's buffer
        assert one.integers(5) == bulk.integers(5)
    want = np.concatenate([one.integers(b, size=m) for b in bounds])
    got = bulk.integers(np.repeat(np.array(bounds, dtype=np.int64), m))
    np.testing.assert_array_equal(got, want)
    assert got.dtype == want.dtype == np.int64
    assert bulk.bit_generator.state == one.bit_generator.state
    assert bulk.integers(1 << 62) == one.integers(1 << 62)


def _walks(rng: np.random.Generator, n: int, length: int) -> list[F64]:
    runs = []
    for _ in range(n):
        k = int(rng.integers(length // 4, length + 1))
        xy = np.cumsum(rng.normal(0, 2, (k, 2)), axis=0) + rng.uniform(0, 60, 2)
        runs.append(np.column_stack([np.arange(k, dtype=float), xy]))
    return runs


@pytest.mark.parametrize("chunk", [1, 7, calibrate.DRAW_CHUNK])
@pytest.mark.parametrize("seed", range(8))
def test_artificial_gaps_with_regions_are_one_attempt_at_a_time(
    seed: int, chunk: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With square regions, the gaps, their marks and the generator's state after them are
    those of one draw per attempt (the reference), stretches running out included, whatever
    the attempts drawn at a time (a chunk ending before, at or after the n-th gap)."""
    monkeypatch.setattr(calibrate, "DRAW_CHUNK", chunk)
    rng = np.random.default_rng(seed)
    runs = _walks(rng, int(rng.integers(3, 25)), 80)
    flat = _flat(runs)
    blocks = _region_blocks(flat, float(rng.uniform(4, 20)), np.random.default_rng(seed))
    targets = [
        (int(rng.integers(1, 30)), float(rng.exponential(6)), int(rng.integers(1, 14)), 4)
        for _ in range(int(rng.integers(1, 8)))
    ]
    n = int(rng.integers(5, 400))
    got_rng, want_rng = np.random.default_rng([seed, 2]), np.random.default_rng([seed, 2])
    got_marks: list[bool] = []
    want_marks: list[bool] = []
    got = _artificial_gaps(runs, targets, n, got_rng, flat, blocks, got_marks)
    want = artificial_gaps(runs, targets, n, want_rng, blocks, want_marks)
    assert len(got) == len(want) > 0
    assert got_marks == want_marks
    for g, w in zip(got, want, strict=True):
        assert g[3] == w[3]
        assert all(np.array_equal(a, b) for a, b in zip(g[:3], w[:3], strict=True))
    assert got_rng.bit_generator.state == want_rng.bit_generator.state


class _Counting:
    """A generator that counts its ``integers`` calls."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng = rng
        self.calls = 0

    def integers(self, *args: Any, **kwargs: Any) -> Any:
        self.calls += 1
        return self.rng.integers(*args, **kwargs)

    def permutation(self, *args: Any, **kwargs: Any) -> Any:
        return self.rng.permutation(*args, **kwargs)

    @property
    def bit_generator(self) -> np.random.BitGenerator:
        return self.rng.bit_generator


def test_the_attempts_are_one_draw() -> None:
    """Every attempt drawn in one ``integers`` call, and one more to draw again those taken when
    the gaps are cut before the last (was one call per attempt: 60 here, and more where places
    repeat)."""
    runs = _walks(np.random.default_rng(0), 30, 400)
    counting = _Counting(np.random.default_rng(1))
    want_rng = np.random.default_rng(1)
    got = _artificial_gaps(runs, [(3, -1.0)], 60, counting)  # type: ignore[arg-type]
    want = artificial_gaps(runs, [(3, -1.0)], 60, want_rng)
    assert len(got) == len(want) == 60
    assert all(np.array_equal(g[2], w[2]) for g, w in zip(got, want, strict=True))
    assert counting.bit_generator.state == want_rng.bit_generator.state
    assert counting.calls <= 2


@pytest.mark.parametrize("n", [5, 40, 300, 700])
def test_many_attempts_in_chunks_are_one_attempt_at_a_time(n: int) -> None:
    """More attempts than a chunk (4 n past DRAW_CHUNK; few places, so most attempts repeat
    one): the same gaps and state as the reference, in a few calls."""
    runs = _walks(np.random.default_rng(n), 6, 40)
    targets = [(4, 3.0, 3, 3), (9, 5.0, 2, 8), (200, 1.0, 3, 3)]  # 200: no run has room
    counting = _Counting(np.random.default_rng([n, 5]))
    want_rng = np.random.default_rng([n, 5])
    got = _artificial_gaps(runs, targets, n, counting)  # type: ignore[arg-type]
    want = artificial_gaps(runs, targets, n, want_rng)
    assert len(got) == len(want) > 0
    for g, w in zip(got, want, strict=True):
        assert g[3] == w[3]
        assert all(np.array_equal(a, b) for a, b in zip(g[:3], w[:3], strict=True))
    assert counting.bit_generator.state == want_rng.bit_generator.state
    assert counting.calls <= 2 * (4 * n // calibrate.DRAW_CHUNK + 1) + 1
