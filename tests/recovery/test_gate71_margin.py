"""The jump rule's margin: no true hole of eight ground truths refused (issue 12, stop 71).

:func:`pftrack.recovery.fill.jump_holes` leaves a hole unfilled when its sides are more than
:data:`~pftrack.recovery.fill.JUMP_FACTOR` times too far apart for one object. On the holes of
the five real ground truths and three synthetic scenes, cut by the automatic masks of
``pftrack experiment gaps`` and by a fifth of the rows dropped, it must refuse none, with a
margin of 2; on ids handed on at a frame (three patterns, five frames) it catches most of the
holes that span the hand-over (docs/recovery.md, "A hole between two objects is left").
"""

from __future__ import annotations

import configparser
from pathlib import Path

import numpy as np
import pytest

from pftrack.io.mot import read_mot
from pftrack.recovery.experiment import auto_masks, trajectories
from pftrack.recovery.fill import JUMP_FACTOR, jump_holes
from pftrack.synthetic import make_scene

from ..conftest import dataset

REAL = {
    "PETS09-S2L1": ("pets09-s2l1", (768, 576)),  # its gt.txt is in 768x576 coordinates
    "TUD-Campus": ("tud-campus", None),
    "ADL-Rundle-6": ("mot15-gt/ADL-Rundle-6", None),
    "ETH-Sunnyday": ("mot15-gt/ETH-Sunnyday", None),
    "KITTI-17": ("mot15-gt/KITTI-17", None),
}
PATTERNS = ("next", "random", "nearest")


def _ratios(rows: np.ndarray) -> np.ndarray:
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    holes = np.flatnonzero((r[1:, 1] == r[:-1, 1]) & (np.diff(r[:, 0]) > 1))
    return jump_holes(r, holes)


def _masked(rows: np.ndarray, size: tuple[int, int]) -> list[np.ndarray]:
    """One file per automatic mask of ``pftrack experiment gaps``: the points inside removed."""
    cx, cy = rows[:, 2] + 0.5 * rows[:, 4], rows[:, 3] + 0.5 * rows[:, 5]
    out = []
    for mx, my, mw, mh in auto_masks(trajectories(rows), *size):
        inside = (cx >= mx) & (cx < mx + mw) & (cy >= my) & (cy < my + mh)
        out.append(rows[~inside])
    return out


def _handed_on(rows: np.ndarray, frame: int, pattern: str, seed: int) -> np.ndarray:
    """A fifth of the rows dropped; the ids alive on both sides of `frame` handed on after it.

    The true id rides in column 8 (the holes whose sides differ there bridge two objects).
    """
    rng = np.random.default_rng(seed)
    r = rows[rng.random(len(rows)) >= 0.2].copy()
    r[:, 7] = r[:, 1]
    ids = np.intersect1d(r[r[:, 0] <= frame, 1], r[r[:, 0] > frame, 1])
    if pattern == "next":
        new = np.roll(ids, -1)
    elif pattern == "random":
        new = ids
        while len(ids) > 1 and np.any(new == ids):
            new = rng.permutation(ids)
    else:  # each id swapped with the nearest other object at the frame: the hardest
        new = ids.copy()
        last = []
        for i in ids:
            mine = rows[(rows[:, 1] == i) & (rows[:, 0] <= frame)]
            last.append(mine[np.argmax(mine[:, 0])])
        centre = np.array(last)[:, 2:4] + 0.5 * np.array(last)[:, 4:6]
        d = np.hypot(*(centre[:, None] - centre[None]).transpose(2, 0, 1))
        d[np.diag_indices(len(ids))] = np.inf
        used: set[int] = set()
        for flat in np.argsort(d, axis=None):
            a, b = np.unravel_index(flat, d.shape)
            if a < b and a not in used and b not in used:
                used |= {int(a), int(b)}
                new[a], new[b] = ids[b], ids[a]
    mapping = dict(zip(ids.tolist(), new.tolist(), strict=True))
    late = r[:, 0] > frame
    r[late, 1] = [mapping.get(i, i) for i in r[late, 1].tolist()]
    return r


def _truth(name: str, tmp_path: Path) -> tuple[np.ndarray, tuple[int, int]]:
    if name.startswith("synthetic"):
        path = tmp_path / f"{name}.txt"
        make_scene(n_frames=300, n_walkers=12, rng=int(name[-1])).write_truth(path)
        return np.asarray(read_mot(path), dtype=np.float64), (480, 360)
    sub, size = REAL[name]
    folder = dataset(sub)
    if size is None:
        ini = configparser.ConfigParser()
        ini.read(folder / "seqinfo.ini")
        size = (int(ini["Sequence"]["imWidth"]), int(ini["Sequence"]["imHeight"]))
    return np.asarray(read_mot(folder / "gt.txt"), dtype=np.float64), size


NAMES = [*REAL, "synthetic0", "synthetic1", "synthetic2"]


@pytest.fixture(scope="module")
def measured(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per truth: the ratios of its true holes and of the holes that bridge a hand-over."""
    out = {}
    tmp = tmp_path_factory.mktemp("truths")
    for name in NAMES:
        try:
            rows, size = _truth(name, tmp)
        except pytest.skip.Exception:
            continue
        true = [_ratios(f) for f in [rows, *_masked(rows, size)]]
        bridging = []
        frames = np.unique(rows[:, 0])
        for k, frame in enumerate(np.quantile(frames, [0.2, 0.35, 0.5, 0.65, 0.8]).astype(int)):
            for j, pattern in enumerate(PATTERNS):
                r = _handed_on(rows, int(frame), pattern, 100 * k + j)
                r = r[np.lexsort((r[:, 0], r[:, 1]))]
                holes = np.flatnonzero((r[1:, 1] == r[:-1, 1]) & (np.diff(r[:, 0]) > 1))
                ratio = jump_holes(r, holes)
                two = r[holes, 7] != r[holes + 1, 7]
                true.append(ratio[~two])
                bridging.append(ratio[two])
        out[name] = (np.concatenate(true), np.concatenate(bridging))
    return out


@pytest.mark.parametrize("name", NAMES)
def test_no_true_hole_is_refused_with_a_margin_of_2(
    measured: dict[str, tuple[np.ndarray, np.ndarray]], name: str
) -> None:
    if name not in measured:
        pytest.skip(f"{name}: data absent")
    true, bridging = measured[name]
    assert len(true) > 800 and len(bridging) > 15
    assert true.max() < JUMP_FACTOR / 2  # ETH-Sunnyday's largest: 1.87


def test_most_holes_across_a_hand_over_are_refused(
    measured: dict[str, tuple[np.ndarray, np.ndarray]],
) -> None:
    if len(measured) < len(NAMES):
        pytest.skip("data absent")
    bridging = np.concatenate([b for _, b in measured.values()])
    caught = float(np.mean(bridging > JUMP_FACTOR))
    assert len(bridging) > 200
    assert caught > 0.6  # 157 of 249 on 7 December (a hand-over to a neighbour is missed)
