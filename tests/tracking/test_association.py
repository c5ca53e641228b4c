"""The padded cost matrices :func:`pftrack.tracking.association.associate` keeps between frames,
and its colour product on one BLAS thread."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pftrack import _threads
from pftrack.tracking import AssociationConfig, association


def test_the_kept_padding_matrices_stay_small_in_a_long_run_of_crowds() -> None:
    # was: every (tracks, detections) shape kept, up to 256 of them: a service tracking crowds
    # of 150-180 people held 213 MB of them after 60 frames, 32 MB for each 1000 + 1000 shape
    association._PADDING.clear()
    try:
        for n in range(150, 180):
            for extra in (0, 7):
                padded = association._padding(n, n + extra, 3.0)
                assert padded.shape == (2 * n + extra, 2 * n + extra)
        for n in range(1, 30):  # the small matrices of ordinary scenes are still kept
            association._padding(n, n + 1, 3.0)
        kept = sum(p.nbytes for p in association._PADDING.values())
        assert kept <= 16 * 2**20
        assert kept <= association._PADDING_KEPT * association._PADDING_LARGEST
        assert association._padding(5, 6, 3.0) is association._padding(5, 6, 3.0)
    finally:
        association._PADDING.clear()


def test_a_padding_matrix_too_large_to_keep_is_the_same_matrix() -> None:
    nt, nd, tau = 120, 90, 2.5
    padded = association._padding(nt, nd, tau)
    assert not padded.flags.writeable
    want = np.full((nt + nd, nd + nt), association.FORBIDDEN)
    want[np.arange(nt), nd + np.arange(nt)] = tau
    want[nt + np.arange(nd), np.arange(nd)] = tau
    want[nt:, nd:] = 0.0
    np.testing.assert_array_equal(padded, want)


def _blas_or_skip() -> tuple[Callable[[], int], Callable[[int], object]]:
    blas = _threads.openblas_threads()
    if not isinstance(blas, tuple):
        pytest.skip("NumPy's BLAS is not the OpenBLAS of NumPy's wheels")
    return blas


def _one_thread_products(
    tmp_path: Path, pairs: list[tuple[np.ndarray, np.ndarray]]
) -> list[np.ndarray]:
    """`a @ b` of each pair in a fresh process whose OpenBLAS has one thread (the reference)."""
    for k, (a, b) in enumerate(pairs):
        np.save(tmp_path / f"a{k}.npy", a)
        np.save(tmp_path / f"b{k}.npy", b)
    code = (
        "import sys, numpy as np\n"
        "d, n = sys.argv[1], int(sys.argv[2])\n"
        "for k in range(n):\n"
        "    np.save(f'{d}/c{k}.npy', np.load(f'{d}/a{k}.npy') @ np.load(f'{d}/b{k}.npy').T)\n"
    )
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    subprocess.run(
        [sys.executable, "-c", code, str(tmp_path), str(len(pairs))], env=env, check=True
    )
    return [np.load(tmp_path / f"c{k}.npy") for k in range(len(pairs))]


def test_the_colour_product_of_a_crowd_has_one_blas_threads_bits(tmp_path: Path) -> None:
    # was `sqrt(references) @ sqrt(hists).T` on OpenBLAS's pool from about 70 x 70: 0.24-2.6 ms
    # of CPU a product at 100 x 100 against 0.06-0.09, and sums that differ from one thread's (what
    # `pftrack track` runs) in their last bits, so a library tracker of 70+ tracks weighed its
    # pairs otherwise than the command, and than itself on a machine of another core count
    get, put = _blas_or_skip()
    rng = np.random.default_rng(3)
    shapes = [(75, 75), (70, 71), (100, 100), (100, 102), (150, 151), (49, 50), (24, 30)]
    pairs = [
        (np.sqrt(rng.random((t, 110)) / 110), np.sqrt(rng.random((d, 110)) / 110))
        for t, d in shapes
    ]
    want = _one_thread_products(tmp_path, pairs)
    before = get()
    put(2)
    try:
        got = [association.colour_product(a, b.T) for a, b in pairs]
        assert get() == 2  # set back after each product
    finally:
        put(before)
    for (t, d), g, w in zip(shapes, got, want, strict=True):
        assert g.tobytes() == w.tobytes(), (t, d)


def test_a_small_colour_product_is_numpys_own() -> None:
    rng = np.random.default_rng(4)
    a, b = np.sqrt(rng.random((10, 110))), np.sqrt(rng.random((12, 110)))
    assert association.colour_product(a, b.T).tobytes() == (a @ b.T).tobytes()
    assert 10 * 12 * 110 <= association.ONE_THREAD_PRODUCT  # the bench's frames: not touched


def test_associate_takes_its_colours_from_the_one_thread_product(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen: list[tuple[tuple[int, ...], tuple[int, ...]]] = []

    def spy(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        seen.append((a.shape, b.shape))
        return a @ b

    monkeypatch.setattr(association, "colour_product", spy)
    boxes = np.array([[10.0, 10, 20, 40], [60, 10, 20, 40]])
    hists = np.full((2, 110), 1 / 110)
    out = association.associate(
        boxes, boxes[:, 3], np.zeros(2, np.int64), hists, boxes, hists, AssociationConfig()
    )
    assert seen == [((2, 110), (110, 2))]
    assert out.matches == [(0, 0), (1, 1)]
