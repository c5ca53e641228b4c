"""The size-for-row rule (`LifecycleConfig.size_ratio`) on a check set fixed before measuring.

docs/tracking.md, "A fresh check, its rule fixed before measuring" and "A guard: the line must
explain the heights": four settings, each run on every row of the sets below with
``camera_motion`` ``auto`` and ``off``, tracker seed 0, given detections, scored by
`pftrack.eval.evaluate_sequence` (MOTA, IDF1, HOTA):

``off``
    ``size_ratio`` None (the default until C passed this check; 0.8 since).
``A``
    ``size_ratio`` 0.8 with both limits: not after the camera was found moving (limit 1), no
    row outside the fitted foot rows' 5th-95th percentile judged (limit 2,
    `pftrack.tracking.offline.SIZE_ROWS`); no guard (``SIZE_SPREADS`` None while it runs).
``B``
    ``size_ratio`` 0.8 with limit 1 alone (``SIZE_ROWS`` and ``SIZE_SPREADS`` None).
``C``
    ``size_ratio`` 0.8 with both limits and the guard (the code as it stands: a class is
    judged only if the line explains its detections' heights, `offline.size_line`).

The set of helper sizefresh (``--sets moving paths still``, the default):

(a) ``moving``: `pftrack.synthetic.make_scene` (rng 1, 2, 3; 8 walkers, 150 frames) and
    `make_busy_scene` ``present`` and ``groups`` (rng 1), each filmed by `move_camera`'s
    default path and by the ``tilt`` path below, with detections made from the moved truth as
    `experiments.public_detections` makes the synthetic scenes' (`noisy_detections`, its seed
    the scene's: jitter, misses, a false box every other frame).
(b) ``paths``: PETS09-S2L1 and TUD-Campus (video, public ``det.txt``) along ``tilt`` (zoom
    1.3, the view moved up and down by 6 % of the height, one cycle over the sequence),
    ``slowpan`` (zoom 1.3, a steady sweep over 14 % of the width) and ``zoomout`` (zoom 1.5 to
    1.05, steadily): truth and detections moved with the frames as in
    `experiments.moving_camera` (`warp_rows`), frames warped in memory as they are read.
(c) ``still``: `make_scene` rng 1, 2, 3 (people of any size at any row) and `make_busy_scene`
    ``overhead`` rng 1 and 2 (bird's-eye, one size everywhere), detections as in (a).

The fresh set of helper sizefit (``--sets moving2 paths2 still2``), fixed before C was run:

(a) ``moving2``: `make_scene` rng 4 and 5 (8 walkers, 150 frames), `move_camera`'s default path.
(b) ``paths2``: PETS09-S2L1 and TUD-Campus along ``zoomin`` (zoom 1.05 to 1.5, steadily),
    ``halfzoom`` (zoom 1.5 to 1.05 over the first half, then 1.05) and ``panback`` (zoom 1.3,
    the ``slowpan`` sweep the other way, right to left).
(c) ``still2``: `make_scene` rng 4 to 8 and `make_busy_scene` ``present`` and ``groups`` rng 2
    and 3.

``--public`` adds the eight sequences of `experiments.public_detections` (seed 0) under each
setting. The decision rule (:func:`verdict`) is the one written in docs before the first run.

Usage (from the repository root)::

    python -m experiments.size_check [--data ../shared/data] [--out DIR] [--public]
        [--sets moving paths still moving2 paths2 still2] [--candidates off A B C]
"""

from __future__ import annotations

import contextlib
import dataclasses
import unittest.mock
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from experiments._common import (
    PETS,
    TUD,
    Source,
    data_root,
    experiment_parser,
    no_video_folders,
    tee_stdout,
    video_folders,
)
from experiments.public_detections import noisy_detections, run_all
from pftrack._typing import F64
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.io.mot import as_written, group_by_frame, read_mot
from pftrack.io.video import FrameSource
from pftrack.synthetic import (
    BUSY_SCENES,
    Scene,
    make_busy_scene,
    make_scene,
    move_camera,
    warp_frame,
    warp_rows,
)
from pftrack.tracking import TrackerConfig, track_frames
from pftrack.tracking import offline as offline_pass

CANDIDATES = ("off", "A", "B", "C")
MODES = ("auto", "off")
PATHS = ("tilt", "slowpan", "zoomout")
PATHS2 = ("zoomin", "halfzoom", "panback")  # the fresh set of helper sizefit
SETS = ("moving", "paths", "still", "moving2", "paths2", "still2")
MOVING_SCENES = (("walkers", 1), ("walkers", 2), ("walkers", 3), ("present", 1), ("groups", 1))
STILL_SCENES = (("walkers", 1), ("walkers", 2), ("walkers", 3), ("overhead", 1), ("overhead", 2))
MOVING_SCENES2 = (("walkers", 4), ("walkers", 5))
STILL_SCENES2 = tuple(("walkers", k) for k in range(4, 9)) + tuple(
    (kind, k) for kind in ("present", "groups") for k in (2, 3)
)
FALL = 0.3  # the most a fresh row's MOTA, IDF1 or HOTA may fall against off (points)

Frames = Sequence[NDArray[np.uint8]] | Callable[[], Iterator[NDArray[np.uint8]]]


@dataclasses.dataclass(frozen=True)
class Row:
    """One row of the check set: frames (a list, or a function giving them afresh), truth and
    detections ``{frame: (k, 5)}`` in the frames' pixels."""

    group: str
    name: str
    frames: Frames
    n_frames: int
    truth: F64
    detections: Mapping[int, F64]


@contextlib.contextmanager
def candidate(name: str) -> Iterator[TrackerConfig]:
    """The `TrackerConfig` of setting `name` (``off``, ``A``, ``B``, ``C``), A's and B's
    ``SIZE_SPREADS`` (and B's ``SIZE_ROWS``) patched for as long as it runs."""
    if name not in CANDIDATES:
        raise ValueError(f"candidate is {name!r}, expected one of {CANDIDATES}")
    config = TrackerConfig()
    if name == "off":  # None set here: 0.8 is the default since C passed
        yield dataclasses.replace(
            config, lifecycle=dataclasses.replace(config.lifecycle, size_ratio=None)
        )
        return
    life = dataclasses.replace(config.lifecycle, size_ratio=0.8)
    config = dataclasses.replace(config, lifecycle=life)
    if name == "C":
        yield config
        return
    with contextlib.ExitStack() as patches:
        patches.enter_context(unittest.mock.patch.object(offline_pass, "SIZE_SPREADS", None))
        if name == "B":
            patches.enter_context(unittest.mock.patch.object(offline_pass, "SIZE_ROWS", None))
        yield config


def path_affines(kind: str, n_frames: int, size: tuple[int, int]) -> F64:
    """One source-to-image affine per frame (`camera_path`'s convention) for path `kind`.

    With ``u = t / (T - 1)``: ``tilt`` zooms 1.3 and moves the view down and up by 6 % of the
    height (``sin(2 pi u)``); ``slowpan`` zooms 1.3 and sweeps the view steadily from 7 % of
    the width left of the centre to 7 % right of it (``panback``: from right to left);
    ``zoomout`` zooms from 1.5 to 1.05 steadily about the centre, ``zoomin`` from 1.05 to 1.5,
    ``halfzoom`` from 1.5 to 1.05 over the first half (``u <= 0.5``), then stays. None rolls.
    """
    if kind not in PATHS + PATHS2:
        raise ValueError(f"path is {kind!r}, expected one of {PATHS + PATHS2}")
    h, w = size
    u = np.linspace(0.0, 1.0, n_frames) if n_frames > 1 else np.zeros(1)
    zoom = np.full(n_frames, 1.3)
    shift = np.zeros((n_frames, 2))
    if kind == "tilt":
        shift[:, 1] = 0.06 * h * np.sin(2 * np.pi * u)
    elif kind in ("slowpan", "panback"):
        shift[:, 0] = 0.07 * w * (2 * u - 1) * (1 if kind == "slowpan" else -1)
    elif kind == "zoomout":
        zoom = 1.5 - 0.45 * u
    elif kind == "zoomin":
        zoom = 1.05 + 0.45 * u
    else:
        zoom = 1.5 - 0.45 * np.minimum(2 * u, 1.0)
    c = np.array([w / 2, h / 2])
    out = np.zeros((n_frames, 2, 3))
    for k in range(n_frames):
        # u = c + z (x - c - shift), as camera_path without roll
        out[k, 0, 0] = out[k, 1, 1] = zoom[k]
        out[k, :, 2] = c - zoom[k] * (c + shift[k])
    return out


def as_detections(rows: F64) -> dict[int, F64]:
    """MOT detection rows as ``{frame: (k, 5) [left, top, w, h, score]}`` (`load_detections`)."""
    return {f: np.column_stack([r[:, 2:6], r[:, 6]]) for f, r in group_by_frame(rows).items()}


def synthetic_rows(sets: Sequence[str], n_frames: int = 150) -> Iterator[Row]:
    """The synthetic rows of ``moving``, ``still``, ``moving2`` and ``still2`` in `sets`;
    `n_frames` for `make_scene`."""

    def scene(kind: str, seed: int) -> Scene:
        if kind == "walkers":
            return make_scene(n_frames=n_frames, n_walkers=8, rng=seed)
        return make_busy_scene(kind, rng=seed)

    def row(group: str, name: str, frames: list[NDArray[np.uint8]], truth: F64, seed: int) -> Row:
        h, w = frames[0].shape[:2]
        dets = noisy_detections(truth, len(frames), h, w, seed=seed)
        return Row(group, name, frames, len(frames), truth, dets)

    if "moving" in sets:
        for kind, seed in MOVING_SCENES:
            s = scene(kind, seed)
            moved = move_camera(s)
            yield row("moving", f"{kind} {seed} default path", moved.frames, moved.truth, seed)
            affines = path_affines("tilt", len(s.frames), (s.height, s.width))
            frames = [warp_frame(f, a) for f, a in zip(s.frames, affines, strict=True)]
            truth = warp_rows(s.truth, affines, (s.height, s.width))
            yield row("moving", f"{kind} {seed} tilt", frames, truth, seed)
    if "still" in sets:
        for kind, seed in STILL_SCENES:
            s = scene(kind, seed)
            yield row("still", f"{kind} {seed}", s.frames, s.truth, seed)
    if "moving2" in sets:
        for kind, seed in MOVING_SCENES2:
            moved = move_camera(scene(kind, seed))
            yield row("moving2", f"{kind} {seed} default path", moved.frames, moved.truth, seed)
    if "still2" in sets:
        for kind, seed in STILL_SCENES2:
            s = scene(kind, seed)
            yield row("still2", f"{kind} {seed}", s.frames, s.truth, seed)


def video_rows(
    data: Path,
    sources: Sequence[Source] = (PETS, TUD),
    paths: Sequence[str] = PATHS,
    affines_of: Callable[[str, int, tuple[int, int]], F64] = path_affines,
    group: str = "paths",
) -> Iterator[Row]:
    """The rows of (b) ``paths``: each of `sources` (PETS09-S2L1, TUD-Campus) along each of
    `paths` (`affines_of` gives a path's affines from its name, frame count and size), its
    truth and detections in the video's pixels moved with the frames."""
    for src, folder in video_folders(data, sources):
        video = folder / src.video
        n, h, w = 0, 0, 0
        for frame in FrameSource(video):  # counted as read: a container's count can be off
            n, (h, w) = n + 1, frame.shape[:2]
        gt, det = (read_mot(folder / name) for name in ("gt.txt", "det.txt"))
        gt[:, 2:6] *= src.scale
        det[:, 2:6] *= src.scale
        for kind in paths:
            affines = affines_of(kind, n, (h, w))

            def frames(a: F64 = affines, v: Path = video) -> Iterator[NDArray[np.uint8]]:
                return (warp_frame(f, a[k]) for k, f in enumerate(FrameSource(v)))

            dets = as_detections(warp_rows(det, affines, (h, w)))
            truth = warp_rows(gt, affines, (h, w))
            yield Row(group, f"{src.name} {kind}", frames, n, truth, dets)


class _Frames(Sequence[NDArray[np.uint8]]):
    """Frames given by a function, read in order (a moved video: nothing held in memory)."""

    def __init__(self, make: Callable[[], Iterator[NDArray[np.uint8]]], n: int) -> None:
        self._make, self._n = make, n

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, i: int) -> NDArray[np.uint8]:  # type: ignore[override]
        raise TypeError("moved video frames are read in order, not by index")

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        return self._make()


def score(row: Row, name: str, mode: str) -> SequenceScores:
    """`row` tracked under setting `name` with ``camera_motion`` `mode`, seed 0, scored."""
    frames = row.frames
    if callable(frames):
        frames = _Frames(frames, row.n_frames)
    with candidate(name) as config:
        config = dataclasses.replace(config, camera_motion=mode)
        run = track_frames(frames, detections=row.detections, config=config, rng=0)
    return evaluate_sequence(row.truth, as_written(run.rows))


def figures(s: SequenceScores) -> F64:
    """MOTA, IDF1, HOTA in %."""
    return 100 * np.array([s.mot.mota, s.mot.idf1, s.hota.hota])


def verdict(
    fresh: Mapping[str, Mapping[str, F64]],
    public: Mapping[str, Mapping[str, F64]] | None,
    pooled: Mapping[str, F64] | None,
) -> tuple[dict[str, list[str]], str]:
    """The rule of docs/tracking.md, "A fresh check, its rule fixed before measuring".

    `fresh` and `public` map each row to each setting's MOTA / IDF1 / HOTA (``off`` and the
    candidates run, e.g. ``A``, ``B``); `pooled` each setting's pooled public figures. Returns,
    per candidate, the reasons it fails (empty: it passes), and the one chosen (``off`` when
    none passes): no fresh row below off by more than `FALL` in any figure, no public sequence
    below off in any, the pooled public MOTA above off's; of two that pass, the higher pooled
    public MOTA (of equal ones, the first in `CANDIDATES`).
    """
    names = ("MOTA", "IDF1", "HOTA")
    fails: dict[str, list[str]] = {}
    judged = [c for c in CANDIDATES if c != "off" and all(c in by for by in fresh.values())]
    for c in judged:
        why = []
        for row, by in fresh.items():
            for k, d in enumerate(by[c] - by["off"]):
                if d < -FALL:
                    why.append(f"{row}: {names[k]} {d:+.2f}")
        if public is None or pooled is None:
            why.append("the public sequences were not run")
        else:
            for row, by in public.items():
                for k, d in enumerate(by[c] - by["off"]):
                    if d < 0:
                        why.append(f"public {row}: {names[k]} {d:+.2f}")
            if not pooled[c][0] > pooled["off"][0]:
                why.append(
                    f"pooled public MOTA {pooled[c][0]:.1f} not above {pooled['off'][0]:.1f}"
                )
        fails[c] = why
    passed = [c for c in judged if not fails[c]]
    if not passed or pooled is None:
        return fails, "off"
    return fails, max(passed, key=lambda c: (pooled[c][0], -CANDIDATES.index(c)))


def public_names(data: Path) -> list[str]:
    """The names of the sequences `run_all` runs under `data`, in its order."""
    names = [src.name for src, _ in video_folders(data)]
    names += [f"{name} (black)" for name, _ in no_video_folders(data)]
    return names + list(BUSY_SCENES)


def cell(a: F64) -> str:
    return f"{a[0]:.1f} / {a[1]:.1f} / {a[2]:.1f}"


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("size_check", __doc__)
    p.add_argument(
        "--sets", nargs="+", choices=SETS, default=list(SETS[:3]),
        help="which parts of the check sets to run (default: moving paths still, helper "
        "sizefresh's set; moving2 paths2 still2 is helper sizefit's)",
    )  # fmt: skip
    p.add_argument(
        "--candidates", nargs="+", choices=CANDIDATES[1:], default=list(CANDIDATES[1:]),
        help="the settings run beside off (default: A B C)",
    )  # fmt: skip
    p.add_argument(
        "--public", action="store_true",
        help="also run the eight sequences of experiments.public_detections under each setting",
    )  # fmt: skip
    args = p.parse_args(argv)
    data = data_root(args.data)
    names = ["off", *(c for c in CANDIDATES if c in args.candidates)]
    rows: list[Row] = list(synthetic_rows(args.sets))
    if "paths" in args.sets:
        rows += list(video_rows(data))
    if "paths2" in args.sets:
        rows += list(video_rows(data, paths=PATHS2, group="paths2"))
    fresh: dict[str, dict[str, F64]] = {}
    public: dict[str, dict[str, F64]] | None = None
    pooled: dict[str, F64] | None = None
    with tee_stdout(args.out / "size_check.md"):
        print("| set | row | camera motion | " + " | ".join(names) + " |")
        print("|---|---|---|" + "---|" * len(names))
        for row in sorted(rows, key=lambda r: SETS.index(r.group)):
            for mode in MODES:
                by = {c: figures(score(row, c, mode)) for c in names}
                fresh[f"{row.group} {row.name} {mode}"] = by
                cells = " | ".join(cell(by[c]) for c in names)
                print(f"| {row.group} | {row.name} | {mode} | {cells} |", flush=True)
        if args.public:
            public, pooled = {}, {}
            for c in names:
                with candidate(c) as config:
                    scores = run_all(data, config, 0)
                for k, s in zip(public_names(data), scores, strict=True):
                    public.setdefault(k, {})[c] = figures(s)
                pooled[c] = figures(SequenceScores.combine(scores))
            print("\n| public sequence | " + " | ".join(names) + " |")
            print("|---|" + "---|" * len(names))
            for k, by in public.items():
                print(f"| {k} | " + " | ".join(cell(by[c]) for c in names) + " |")
            print("| pooled | " + " | ".join(cell(pooled[c]) for c in names) + " |")
        fails, chosen = verdict(fresh, public, pooled)
        print()
        for c, why in fails.items():
            print(f"- {c}: " + ("passes" if not why else "fails: " + "; ".join(why)))
        print(f"- chosen: {chosen}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
