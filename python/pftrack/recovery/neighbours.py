"""Common motion: correct a gap's path by what the other tracks seen over its frames did.

A camera that moves (a rig carried by a walker that bobs, a car that turns) moves every
object in the image together, and no method that looks at one track alone can know how it
moved while the track was lost. The other tracks observed over the same frames saw it: each
such *neighbour* is cut as if it had the same gap (the same frames, the same observed points
on each side), recovered with the same method, and its error on its own known points is the
shared motion the method missed. The gap's path is corrected by the median of those errors,
shrunk toward none as ``n / (n + 1)`` for ``n`` neighbours.

Where objects move independently (a still camera) the neighbours' errors are their own
manoeuvres and the correction only adds noise; ``"auto"`` scores the corrected methods
(``"linear-nb"``, ``"rts-nb"``) on the file's own artificial gaps and keeps them only where
they win (:mod:`pftrack.recovery.calibrate`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from pftrack._stats import median_along
from pftrack._typing import F64
from pftrack.recovery.segments import split_rows

__all__ = [
    "MAX_NEIGHBOURS",
    "NB_SUFFIX",
    "Neighbourhood",
    "correct_by_neighbours",
]

#: At most this many neighbours per gap (the nearest to the gap's last observed point).
MAX_NEIGHBOURS = 8
#: A method name ending in this is the method corrected by its neighbours' errors.
NB_SUFFIX = "-nb"
#: (gap, run) pairs :meth:`Neighbourhood.windows_many` searches at a time (one gap's runs at
#: least), as the linking's and the offline pass's pairs are made. The search takes about 80
#: bytes a pair in temporaries where the runs cover the gaps: was 2**22 pairs, 329 MB of
#: tracemalloc peak for 2000 runs covering 2000 gaps; 13 MB now, the same windows.
SEARCH_BLOCK = 1 << 16

Window = tuple[F64, F64, F64]  # a neighbour cut like the gap: segment A, segment B, truth


class Neighbourhood:
    """Runs of consecutive observed frames, to find those seen over a gap's frames.

    Parameters
    ----------
    runs : sequence of (k, 3+) ndarray
        Rows ``(frame, x, y, ...)`` with consecutive frames (as
        :func:`~pftrack.recovery.segments.distinct_runs` gives them); not copied.
    """

    def __init__(self, runs: Sequence[F64]) -> None:
        self.runs = list(runs)
        self.first = np.array([r[0, 0] for r in self.runs], dtype=np.float64)
        self.last = np.array([r[-1, 0] for r in self.runs], dtype=np.float64)
        sizes = np.array([len(r) for r in self.runs], dtype=np.int64)
        self._offset = np.r_[0, np.cumsum(sizes)[:-1]].astype(np.int64)
        stacked = np.vstack([r[:, :3] for r in self.runs]) if self.runs else np.zeros((0, 3))
        self._frame, self._xy = stacked[:, 0], stacked[:, 1:3]
        self._cache: dict[tuple[float, ...], list[Window]] = {}  # each "-nb" method asks

    def forget(self) -> None:
        """Drop the windows found so far (each is found again, the same, when asked again).

        :func:`~pftrack.recovery.calibrate.recover_auto` forgets them after each block of
        gaps, so they take a block's memory, not every gap's.
        """
        self._cache.clear()

    def windows(self, segment_a: F64, segment_b: F64, exclude: int = -1) -> list[Window]:
        """The neighbours of the gap between `segment_a` and `segment_b`, cut like it.

        A neighbour is a run (other than run `exclude`, the one an artificial gap was cut
        from) observed on every frame from the gap's last point before to its first point
        after. It is cut into as many points before and after as the gap has (fewer where
        the run is shorter) and the points between, its truth. At most
        :data:`MAX_NEIGHBOURS`, nearest first to the gap's last point before (ties: run
        order). :meth:`windows_many` of one pair.
        """
        return self.windows_many([(segment_a, segment_b)], [exclude])[0]

    def windows_many(
        self, pairs: Sequence[tuple[F64, F64]], excludes: Sequence[int]
    ) -> list[list[Window]]:
        """:meth:`windows` of every pair (with its run to leave out), the search vectorised.

        The same windows in the same order: candidate runs of every pair not seen before are
        found and ordered (distance, then run) in a few array operations, in blocks of pairs.
        """
        keys = []
        todo: dict[tuple[float, ...], int] = {}
        for (a, b), e in zip(pairs, excludes, strict=True):
            # the gap's ends, its last point before, the points each side, the run left out
            key = (
                float(a[-1, 0]), float(b[0, 0]), float(a[-1, 1]), float(a[-1, 2]),
                float(len(a)), float(len(b)), float(e),
            )  # fmt: skip
            keys.append(key)
            if key not in self._cache and key not in todo:
                todo[key] = len(todo)
        pending = list(todo)
        n_runs = len(self.runs)
        block = max(1, SEARCH_BLOCK // max(n_runs, 1))  # gaps x runs per block: bounded memory
        for lo in range(0, len(pending), block):
            self._search([k for k in pending[lo : lo + block]])
        return [self._cache[k] for k in keys]

    def _search(self, keys: list[tuple[float, ...]]) -> None:
        """Fill the cache for `keys` ``(fa, fb, x, y, len_a, len_b, exclude)``."""
        K = np.array(keys, dtype=np.float64).reshape(len(keys), 7)
        fa, fb, x, y = K[:, 0], K[:, 1], K[:, 2], K[:, 3]
        ok = (self.first[None, :] <= fa[:, None]) & (self.last[None, :] >= fb[:, None])
        ok &= np.arange(len(self.runs))[None, :] != K[:, 6].astype(np.int64)[:, None]
        pair, idx = np.nonzero(ok)  # row-major: by pair, then run
        at = (fa[pair] - self.first[idx]).astype(np.int64)
        on = self._frame[self._offset[idx] + at] == fa[pair]
        pair, idx, at = pair[on], idx[on], at[on]
        xy = self._xy[self._offset[idx] + at]
        d = np.hypot(xy[:, 0] - x[pair], xy[:, 1] - y[pair])
        order = np.lexsort((idx, d, pair))
        pair, idx, at = pair[order], idx[order], at[order]
        starts = np.searchsorted(pair, np.arange(len(keys) + 1))
        for p, key in enumerate(keys):
            n_a, n_b = int(key[4]), int(key[5])
            n_gap = int(key[1] - key[0]) - 1
            out: list[Window] = []
            for k in range(
                int(starts[p]), min(int(starts[p + 1]), int(starts[p]) + MAX_NEIGHBOURS)
            ):
                r, i = self.runs[int(idx[k])], int(at[k])
                lo = max(0, i + 1 - n_a)
                hi = i + 1 + n_gap + n_b
                out.append((r[lo : i + 1], r[i + 1 + n_gap : hi], r[i + 1 : i + 1 + n_gap]))
            self._cache[key] = out


def correct_by_neighbours(
    recover: Callable[[list[tuple[F64, F64]]], list[F64]],
    pairs: Sequence[tuple[F64, F64]],
    hood: Neighbourhood,
    excludes: Sequence[int] | None = None,
    base: Sequence[F64] | None = None,
) -> list[F64]:
    """Recover `pairs` with `recover`, each path corrected by its neighbours' errors.

    Parameters
    ----------
    recover : callable
        The method: ``recover(pairs) -> paths`` (``(x, y)`` of every frame inside each gap).
    pairs : sequence of (segment_a, segment_b)
        Checked segments (rows ``frame, x, y``).
    hood : Neighbourhood
        The observed runs the neighbours come from.
    excludes : sequence of int, optional
        Per pair, the run of `hood` not to use (an artificial gap's own run); default none.
    base : sequence of ndarray, optional
        ``recover(pairs)`` when the caller has it already (the calibration scored the method
        itself); default: recovered here.

    Returns
    -------
    list of (T_g - 1, 2) ndarray
        The corrected paths; a gap without neighbours keeps the method's path.
    """
    pairs = list(pairs)
    skip = [-1] * len(pairs) if excludes is None else [int(e) for e in excludes]
    base = recover(pairs) if base is None else list(base)
    wins = hood.windows_many(pairs, skip)
    flat = [w for ws in wins for w in ws]
    if not flat:
        return base
    got = recover([(a, b) for a, b, _ in flat])
    # every neighbour's error in one subtraction (rows of the windows' truths and paths)
    diff = np.concatenate([t[:, 1:3] for _, _, t in flat]) - np.concatenate(got)
    errors = split_rows(diff, [len(p) for p in got])
    # The median of each gap's neighbours' errors: one np.median per group of gaps with as
    # many neighbours and frames (each lane's median is the same as gap by gap).
    groups: dict[tuple[int, int], tuple[list[int], list[int]]] = {}
    k = 0
    for g, (path, ws) in enumerate(zip(base, wins, strict=True)):
        n = len(ws)
        if n:
            gaps, starts = groups.setdefault((n, len(path)), ([], []))
            gaps.append(g)
            starts.append(k)
        k += n
    out = list(base)
    for (n, _), (gaps, starts) in groups.items():
        stack = np.stack([np.stack(errors[k : k + n]) for k in starts])
        shared: NDArray[np.float64] = median_along(stack, 1)
        for g, row in zip(gaps, shared, strict=True):
            out[g] = base[g] + row * (n / (n + 1.0))
    return out
