"""Linking over the candidate pairs only equals the dense (K, K) assignment, in bounded work.

Regression (user trial): ``link_tracklets`` allocated a dense ``(K, K)`` matrix and looped in
Python over every pair of ids before testing the time gate, so 8000 one-row fragments ten
frames apart took 34 s and 1.6 GB in ``pftrack smooth``. The references are in
``tests/reference/linking.py`` (the former dense code).
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np
import pytest

import pftrack.recovery.linking as linking
from pftrack.recovery.linking import LinkConfig, link_cost_matrix, link_tracklets, split_tracks
from tests.reference.linking import dense_link_costs, dense_link_tracklets, dense_links


def _fragments(rng: np.random.Generator, k: int, grid: bool = False) -> np.ndarray:
    """`k` fragments of walkers (1-8 rows) starting over 60 frames, some near each other.

    `grid`: integer positions on a 10 px grid and steps of 0 or 5 px, so that many pairs cost
    exactly the same (ties).
    """
    rows = []
    for tid in range(1, k + 1):
        f0, n = int(rng.integers(1, 60)), int(rng.integers(1, 9))
        if grid:
            x, y = rng.integers(0, 5, 2) * 10.0
            vx, vy = float(rng.integers(-1, 2)) * 5, 0.0
            h = 40.0
        else:
            x, y = rng.uniform(0, 200, 2)
            vx, vy = rng.normal(0, 2, 2)
            h = float(rng.uniform(30, 60))
        t = np.arange(n, dtype=np.float64)
        rows.append(np.column_stack([f0 + t, np.full(n, tid), x + vx * t, y + vy * t,
                                     np.full(n, 0.4 * h), np.full(n, h), np.ones(n),
                                     -np.ones((n, 3))]))  # fmt: skip
    out = np.vstack(rows)
    return out[rng.permutation(len(out))]


@pytest.mark.parametrize("dense_cells", [linking.DENSE_CELLS, 0])
def test_sparse_linking_equals_the_dense_assignment(
    monkeypatch: pytest.MonkeyPatch, dense_cells: int
) -> None:
    """Same joins, same rows, same mapping; 0 dense cells: every component by the sparse solver."""
    monkeypatch.setattr(linking, "DENSE_CELLS", dense_cells)
    for seed in range(25):
        rng = np.random.default_rng(seed)
        rows = _fragments(rng, int(rng.integers(2, 60)))
        cfg = LinkConfig(
            max_gap=int(rng.integers(1, 25)),
            max_distance=float(rng.uniform(10, 80)),
            velocity_points=int(rng.integers(1, 6)),
        )
        want_rows, want = dense_link_tracklets(rows, cfg)
        got_rows, got = link_tracklets(rows, cfg)
        assert list(got.items()) == list(want.items()), seed
        assert got_rows.tobytes() == want_rows.tobytes(), seed


def test_sparse_costs_equal_the_dense_matrix_bit_for_bit() -> None:
    for seed in range(5):
        rng = np.random.default_rng(100 + seed)
        rows = _fragments(rng, 50)
        cfg = LinkConfig(max_gap=20, max_distance=60.0)
        ids, want = dense_link_costs(rows, cfg)
        got_ids, got = link_cost_matrix(split_tracks(rows), cfg)
        assert got_ids == ids
        assert got.tobytes() == want.tobytes()


@pytest.mark.parametrize("dense_cells", [linking.DENSE_CELLS, 0])
def test_sparse_linking_is_optimal_on_ties(
    monkeypatch: pytest.MonkeyPatch, dense_cells: int
) -> None:
    """With exact ties several assignments are optimal: as many joins at the same total cost.

    (The dense matrix and its components may pick different ones among equals; on the real
    files compared, PETS09, TUD-Campus, ADL-Rundle-6, ETH-Sunnyday, KITTI-17 split at random
    holes, they never did.)
    """
    monkeypatch.setattr(linking, "DENSE_CELLS", dense_cells)
    for seed in range(25):
        rng = np.random.default_rng(seed)
        rows = _fragments(rng, int(rng.integers(5, 50)), grid=True)
        cfg = LinkConfig(max_gap=int(rng.integers(3, 20)), max_distance=30.0)
        ids, cost = dense_link_costs(rows, cfg)
        at = {t: n for n, t in enumerate(ids)}
        want = dense_links(rows, cfg)
        _, i, j, c = linking.link_costs(split_tracks(rows), cfg)
        got = [(ids[a], ids[b]) for a, b in linking._assign(i, j, c)]
        assert len(got) == len(want), seed
        assert len({a for a, _ in got}) == len({b for _, b in got}) == len(got)
        total = sum(cost[at[a], at[b]] for a, b in got)
        assert total == pytest.approx(sum(cost[at[a], at[b]] for a, b in want), abs=1e-9)


def _bounded_link(rows: np.ndarray) -> tuple[dict[int, int], float, float]:
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        _, mapping = link_tracklets(rows, LinkConfig())
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return mapping, time.perf_counter() - t0, peak / 2**20


@pytest.mark.parametrize(
    ("name", "x"),
    [
        ("50 walkers' positions in turn", lambda i: 100 + (i % 50) * 5),  # the trial's file
        ("one chain, one component", lambda i: 100 + (i % 3)),  # the sparse solver
    ],
)
def test_8000_fragments_link_in_seconds_and_flat_memory(name: str, x: object) -> None:
    """8000 one-row fragments, one every 10 frames: was 34 s and a 512 MB matrix."""
    k = 8000
    i = np.arange(k)
    xs = np.array([x(n) for n in i], dtype=np.float64)  # type: ignore[operator]
    rows = np.column_stack([1 + 10 * i, i + 1, xs, np.full(k, 100.0), np.full(k, 20.0),
                            np.full(k, 40.0), np.full(k, 0.9), -np.ones((k, 3))])  # fmt: skip
    mapping, seconds, megabytes = _bounded_link(rows)
    assert len(mapping) == (7840 if name.startswith("50") else 7999)
    assert megabytes < 60, f"{name}: peak {megabytes:.0f} MB"  # the (K, K) matrix: 512 MB
    assert seconds < 15, f"{name}: {seconds:.1f} s"  # about 1 s on an idle machine


def test_the_sparse_solver_equals_its_numpy_reference_bit_for_bit() -> None:
    """``_core.sparse_assignment`` (C++) makes the joins of the Python loop it replaced (15 s of
    a 20000-fragment file), ties too: the same heap order, the same dual updates."""
    import pftrack._core as _core
    from tests.reference.linking import sparse_assignment

    for seed in range(60):
        rng = np.random.default_rng(seed)
        n_ends, n_starts = int(rng.integers(1, 40)), int(rng.integers(1, 40))
        n = int(rng.integers(0, n_ends * n_starts + 1))
        cells = rng.choice(n_ends * n_starts, size=n, replace=False)
        r, c = (cells // n_starts).astype(np.intp), (cells % n_starts).astype(np.intp)
        order = np.lexsort((c, r))  # by end, then start: as _assign gives them
        r, c = r[order], c[order]
        cost = rng.integers(0, 4, n) * 0.25 if seed % 2 else rng.uniform(0, 3, n)  # ties
        want = sparse_assignment(r, c, cost, n_ends, n_starts)
        got = _core.sparse_assignment(r, c, cost, n_ends, n_starts, linking.FORBIDDEN)
        assert got[0].tolist() == want[0].tolist() and got[1].tolist() == want[1].tolist(), seed


def test_the_sparse_solver_refuses_bad_input() -> None:
    import pftrack._core as _core

    one = np.zeros(1, np.intp)
    cases = [
        ((one, np.zeros(2, np.intp), np.zeros(1), 1, 1), "one length"),
        ((one + 1, one, np.zeros(1), 1, 1), r"r\[0\] is 1, expected 0..0"),
        ((one, one - 1, np.zeros(1), 1, 1), r"c\[0\] is -1, expected 0..0"),
        ((one, one, np.array([np.nan]), 1, 1), r"cost\[0\] is not finite"),
        ((one, one, np.zeros(1), -1, 1), r"n_ends and n_starts must be in 0..2\^24"),
        ((one, one, np.zeros(1), 1, 2**31), r"n_ends and n_starts must be in 0..2\^24"),
    ]
    for args, match in cases:
        with pytest.raises(ValueError, match=match):
            _core.sparse_assignment(*args, linking.FORBIDDEN)


def test_candidate_pairs_in_blocks_are_the_pairs_at_once(monkeypatch: pytest.MonkeyPatch) -> None:
    rows = _fragments(np.random.default_rng(7), 60)
    cfg = LinkConfig(max_gap=20, max_distance=60.0)
    whole = linking.link_costs(split_tracks(rows), cfg)
    monkeypatch.setattr(linking, "PAIR_BLOCK", 5)  # one i's pairs may exceed it: never split
    parts = linking.link_costs(split_tracks(rows), cfg)
    assert whole[0] == parts[0]
    for a, b in zip(whole[1:], parts[1:], strict=True):
        assert a.tobytes() == b.tobytes()


def test_many_fragments_a_frame_link_in_bounded_memory() -> None:
    """A user trial: 20000 one-row fragments, 10 a frame (a crowd's fragmented tracker output):
    every pair within the time gate was gated at once (1.1 GB) and the joins were found in
    Python (15 s)."""
    rng = np.random.default_rng(0)
    k = 20000
    rows = np.column_stack([1 + np.arange(k) // 10, np.arange(1, k + 1), rng.uniform(0, 640, k),
                            rng.uniform(0, 480, k), np.full(k, 30.0), np.full(k, 70.0),
                            np.full(k, 0.9), -np.ones((k, 3))])  # fmt: skip
    mapping, seconds, megabytes = _bounded_link(rows)
    assert len(mapping) > 10000
    assert megabytes < 300, f"peak {megabytes:.0f} MB"  # was 1.1 GB
    assert seconds < 20, f"{seconds:.1f} s"  # about 2 s on an idle machine


def test_gating_memory_follows_the_block_not_the_pairs_within_the_time_gate() -> None:
    """A crowd's fragments: the pairs within the time gate grow with the square of the fragments
    a frame (here 793 600, of which 2.3 % pass the gates). ``link_costs`` gated 2**20 of them
    at once, about 210 bytes each in temporaries: a peak of 159 MB here (now 14 MB), and 225 MB
    in ``pftrack smooth`` of the 500-track file scaled to 5000 tracks over the same 2000 frames
    and cut at every hole (docs/recovery.md). Now :data:`PAIR_BLOCK` pairs at a time."""
    rng = np.random.default_rng(3)
    k = 1600  # one-row fragments, 20 a frame for 80 frames, anywhere in 640 x 480
    rows = np.column_stack([1 + np.arange(k) // 20, np.arange(1, k + 1), rng.uniform(0, 640, k),
                            rng.uniform(0, 480, k), np.full(k, 30.0), np.full(k, 70.0),
                            np.full(k, 0.9), -np.ones((k, 3))])  # fmt: skip
    tracks, cfg = split_tracks(rows), LinkConfig()
    last = np.array([t[-1, 0] for t in tracks.values()])
    within = sum(len(i) for i, _ in linking._candidate_pairs(last, last, cfg.max_gap))
    assert within > 750_000
    tracemalloc.start()
    try:
        _, i, _, _ = linking.link_costs(tracks, cfg)
        peak = tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()
    assert 0 < len(i) < 0.05 * within
    assert peak < 40, f"peak {peak:.0f} MB"  # 2**20 pairs a block: 159 MB


def test_pair_blocks_cover_the_entries_in_order_within_the_block() -> None:
    """Ranges of consecutive entries, each of at most `block` pairs unless it is one entry,
    each as long as the block allows: the linking's and the offline pass's blocks."""
    rng = np.random.default_rng(5)
    for block in (1, 4, 37, 1000):
        counts = rng.integers(0, 12, 500) * (rng.random(500) < 0.8)
        counts[::97] = 60  # entries of more pairs than some blocks
        ranges = list(linking._pair_blocks(counts, block))
        assert [lo for lo, _ in ranges] == [0] + [hi for _, hi in ranges[:-1]]
        assert ranges[-1][1] == len(counts)
        for lo, hi in ranges:
            assert hi > lo and (counts[lo:hi].sum() <= block or hi == lo + 1)
            assert hi == len(counts) or counts[lo : hi + 1].sum() > block
    assert list(linking._pair_blocks(np.zeros(0, np.intp), 8)) == []
