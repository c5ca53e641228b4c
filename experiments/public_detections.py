"""pftrack with given detections on every sequence there is: MOTA, IDF1 and HOTA per sequence.

The drop-in mode (`pftrack.tracking.track_frames` with a ``det.txt``, as ``pftrack track
--detections``), seed 0, default settings, scored with `pftrack.eval.evaluate_sequence`
(TrackEval's HOTA, CLEAR-MOT and IDF1 at IoU 0.5):

``pets09-s2l1``, ``tud-campus``
    The video and its public ``det.txt`` (PETS boxes scaled by 0.625 onto the 480x360 video).
``ADL-Rundle-6``, ``ETH-Sunnyday``, ``KITTI-17`` (``mot15-gt/``)
    No video ships with them: the frames are black images of ``seqinfo.ini``'s size, so the
    colour likelihood and box refinement have nothing to use and what is measured is the rest
    of the tracker (association, motion, birth and death, the offline pass) on real detections.
``present``, ``groups``, ``overhead``
    The synthetic busy scenes of `pftrack.synthetic.make_busy_scene` with detections made from
    their truth, seeded: each box moved and resized by 5 % of its height, 10 % of the boxes
    missed, one false box every other frame. ``--scene-seed N`` makes the three scenes and
    their detections with generator seed N instead of 0: scenes no setting was chosen on.

The last row of each seed, ``pooled``, scores the eight sequences together (TrackEval's
combination). ``--seeds`` repeats the run over several tracker seeds (PETS09's IDF1 moves
by 6 points from one seed to the next, docs/tracking.md), and ``--set`` changes
one `TrackerConfig` field for a trial, e.g. ``--set motion.colour_noise=0.2``. ``--upscale 2``
runs every sequence as footage of twice the resolution (frames resized bilinearly as they are
read, detections and truth scaled): a tracker whose settings fit the frame's size scores the
same. ``--empty 60`` removes every detection of frames 1-60 (a scene that starts empty) and
scores the frames after them; ``--low-scores`` squeezes every score into [0.2, 0.5]
(``0.2 + 0.6 (s - 0.5)`` of the score clipped to [0.5, 1], the ranking kept): a detector
that scores below ``birth_score`` (docs/tracking.md, "Birth threshold").

Usage (from the repository root)::

    python -m experiments.public_detections [--data ../shared/data] [--out DIR]
        [--seeds 0 1 2] [--scene-seed 0] [--upscale 2] [--empty 60] [--low-scores]
        [--set SECTION.FIELD=VALUE ...]
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import (
    data_root,
    experiment_parser,
    no_video_folders,
    tee_stdout,
    video_folders,
)
from pftrack._typing import F64
from pftrack.eval import SequenceScores, evaluate_sequence
from pftrack.io.mot import as_written, group_by_frame, read_mot
from pftrack.io.video import FrameSource, read_seqinfo
from pftrack.synthetic import BUSY_SCENES, make_busy_scene
from pftrack.tracking import TrackerConfig, load_detections, track_frames


class BlackFrames(Sequence[NDArray[np.uint8]]):
    """`n` black BGR frames of one size, one array shared by all (nothing is decoded)."""

    def __init__(self, n: int, width: int, height: int) -> None:
        self._n = n
        self._frame = np.zeros((height, width, 3), np.uint8)
        self._frame.setflags(write=False)

    def __len__(self) -> int:
        return self._n

    def __getitem__(self, i: int) -> NDArray[np.uint8]:  # type: ignore[override]
        if not -self._n <= i < self._n:
            raise IndexError(i)
        return self._frame

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        return (self._frame for _ in range(self._n))


class Resized(Sequence[NDArray[np.uint8]]):
    """The frames of `frames` scaled by `factor` (bilinear) as they are read; `frames` if 1."""

    def __init__(self, frames: Sequence[NDArray[np.uint8]] | FrameSource, factor: float) -> None:
        self._frames = frames
        self._factor = factor

    def __len__(self) -> int:
        return len(self._frames)

    def _resize(self, frame: NDArray[np.uint8]) -> NDArray[np.uint8]:
        if self._factor == 1.0:
            return frame
        h, w = frame.shape[:2]
        size = (round(w * self._factor), round(h * self._factor))
        return np.asarray(cv2.resize(frame, size, interpolation=cv2.INTER_LINEAR), np.uint8)

    def __getitem__(self, i: int) -> NDArray[np.uint8]:  # type: ignore[override]
        if isinstance(self._frames, FrameSource):
            raise TypeError("a video is read in order, not by index")
        return self._resize(self._frames[i])

    def __iter__(self) -> Iterator[NDArray[np.uint8]]:
        return (self._resize(f) for f in self._frames)


@contextlib.contextmanager
def blank_frames_expected() -> Iterator[None]:
    """Silence the tracker's warning that frame 1 is blank: black frames are the point here."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="frame 1 is blank", category=UserWarning)
        yield


def black_frames(folder: Path, factor: float = 1.0) -> BlackFrames:
    """The black frames of a sequence without video: ``seqinfo.ini``'s length and size.

    `factor` scales the size (``--upscale``).
    """
    info = read_seqinfo(folder)
    if info.length is None or info.width is None or info.height is None:
        raise ValueError(f"{folder}/seqinfo.ini: no seqLength/imWidth/imHeight")
    return BlackFrames(info.length, round(info.width * factor), round(info.height * factor))


def scaled(dets: dict[int, F64], factor: float) -> dict[int, F64]:
    """Detections ``{frame: [left, top, w, h, score]}`` with their boxes times `factor`.

    For the synthetic scenes' detections; a ``det.txt`` is scaled as it is read
    (`load_detections`' `scale`).
    """
    return {f: np.column_stack([d[:, :4] * factor, d[:, 4:]]) for f, d in dets.items()}


def noisy_detections(
    truth: F64, n_frames: int, height: int, width: int, seed: int = 0
) -> dict[int, F64]:
    """Detections from truth rows: jittered, 10 % missed, a false box every other frame.

    Returns ``{frame: (k, 5) [left, top, w, h, score]}`` as `load_detections` does.
    """
    rng = np.random.default_rng(seed)
    by_frame = group_by_frame(truth)
    out: dict[int, F64] = {}
    for f in range(1, n_frames + 1):
        r = by_frame.get(f, np.zeros((0, 10)))
        r = r[rng.random(len(r)) >= 0.1]
        boxes = r[:, 2:6].copy()
        boxes += rng.normal(0.0, 0.05, boxes.shape) * boxes[:, 3:4]
        # kept inside the frame, as a detector's boxes are
        x1 = np.clip(boxes[:, 0], 0, width - 4)
        y1 = np.clip(boxes[:, 1], 0, height - 4)
        x2 = np.clip(boxes[:, 0] + boxes[:, 2], x1 + 4, width)
        y2 = np.clip(boxes[:, 1] + boxes[:, 3], y1 + 4, height)
        boxes = np.column_stack([x1, y1, x2 - x1, y2 - y1])
        if f % 2 == 0:
            h = rng.uniform(0.1, 0.3) * height
            false = [rng.uniform(0, width - h / 2), rng.uniform(0, height - h), h / 2, h]
            boxes = np.vstack([boxes, false])
        out[f] = np.column_stack([boxes, rng.uniform(0.5, 1.0, len(boxes))])
    return out


def late_and_low(dets: dict[int, F64], empty: int, low: bool) -> dict[int, F64]:
    """`dets` without frames ``1..empty``; with `low`, scores squeezed into [0.2, 0.5].

    ``--empty`` and ``--low-scores``: ``0.2 + 0.6 (s - 0.5)`` of each score clipped to
    [0.5, 1], the ranking of the scores above 0.5 kept.
    """
    out = {}
    for f, d in dets.items():
        if f <= empty:
            continue
        if low:
            d = np.column_stack([d[:, :4], 0.2 + 0.6 * (np.clip(d[:, 4], 0.5, 1.0) - 0.5)])
        out[f] = d
    return out


def line(name: str, s: SequenceScores) -> str:
    """One row of the table: MOTA, IDF1, HOTA (percent) and identity switches."""
    return (
        f"{name:13s} MOTA {100 * s.mot.mota:6.1f}  IDF1 {100 * s.mot.idf1:5.1f}  "
        f"HOTA {100 * s.hota.hota:5.1f}  IDsw {s.mot.num_switches:3d}"
    )


def add_settings(p: argparse.ArgumentParser, example: str) -> None:
    """The ``--set SECTION.FIELD=VALUE`` option of the experiments (:func:`settings_config`)."""
    p.add_argument(
        "--set", action="append", default=[], metavar="SECTION.FIELD=VALUE", dest="settings",
        help=f"change one TrackerConfig field, e.g. {example} (repeatable; "
        "default: none, every default as is)",
    )  # fmt: skip


def settings_config(p: argparse.ArgumentParser, settings: Sequence[str]) -> TrackerConfig:
    """``TrackerConfig()`` with every ``--set`` applied (:func:`override`); a bad one: exit 2."""
    config = TrackerConfig()
    for setting in settings:
        try:
            config = override(config, setting)
        except ValueError as e:
            p.error(str(e))
    return config


def override(config: TrackerConfig, setting: str) -> TrackerConfig:
    """`config` with one field changed, from ``"SECTION.FIELD=VALUE"`` (or ``"FIELD=VALUE"``).

    The value is converted to the type of the field's current value (``none`` gives None).
    Raises ValueError naming the problem for a malformed setting or an unknown field.
    """
    key, sep, text = setting.partition("=")
    if not sep or not key:
        raise ValueError(f"--set {setting!r}: expected SECTION.FIELD=VALUE")
    path = key.split(".")
    if len(path) > 2:
        raise ValueError(f"--set {setting!r}: at most one section (SECTION.FIELD)")
    owner: object = config if len(path) == 1 else getattr(config, path[0], None)
    field = path[-1]
    if not dataclasses.is_dataclass(owner) or field not in {
        f.name for f in dataclasses.fields(owner)
    }:
        raise ValueError(f"--set {setting!r}: TrackerConfig has no field {key!r}")
    old = getattr(owner, field)
    value: object
    if text.lower() == "none":
        value = None
    elif isinstance(old, bool):
        if text.lower() not in ("true", "false"):
            raise ValueError(f"--set {setting!r}: expected true or false")
        value = text.lower() == "true"
    elif isinstance(old, (int, float)) or old is None:
        try:
            value = type(old)(text) if old is not None else _number(text)
        except ValueError:  # (was "is not a NoneType" for a setting off by default)
            kind = "an int" if isinstance(old, int) else "a number"
            raise ValueError(
                f"--set {setting!r}: {text!r} is not {kind}{' (or none)' if old is None else ''}"
            ) from None
    elif isinstance(old, str):
        value = text
    elif dataclasses.is_dataclass(old):  # (was "'lifecycle' is not a number, flag or name")
        raise ValueError(f"--set {setting!r}: {key!r} is a section: give {key}.FIELD=VALUE")
    else:
        raise ValueError(f"--set {setting!r}: {key!r} is not a number, flag or name")
    new: Any = dataclasses.replace(owner, **{field: value})  # type: ignore[type-var]
    if len(path) == 1:
        checked: TrackerConfig = new
        return checked
    changes: dict[str, Any] = {path[0]: new}
    return dataclasses.replace(config, **changes)


def _number(text: str) -> int | float:
    """An int for an integer literal (e.g. ``max_side=640``), else a float."""
    try:
        return int(text)
    except ValueError:
        return float(text)


def main(argv: list[str] | None = None) -> int:
    p = experiment_parser("public_detections", __doc__)
    p.add_argument(
        "--seeds", type=int, nargs="+", default=[0], metavar="SEED",
        help="tracker seeds, one run of every sequence each (default: 0)",
    )  # fmt: skip
    p.add_argument(
        "--scene-seed", type=int, default=0, metavar="N",
        help="generator seed of the synthetic scenes and of their detections (default: 0, "
        "the scenes every setting was chosen on)",
    )  # fmt: skip
    p.add_argument(
        "--upscale", type=float, default=1.0, metavar="FACTOR",
        help="scale every sequence's frames, detections and truth by FACTOR, as footage of "
        "the same scene at another resolution (default: 1.0, as they are)",
    )  # fmt: skip
    p.add_argument(
        "--empty", type=int, default=0, metavar="N",
        help="remove every detection of frames 1..N (a scene that starts empty) and score the "
        "frames after them (default: 0)",
    )  # fmt: skip
    p.add_argument(
        "--low-scores", action="store_true",
        help="squeeze every detection score into [0.2, 0.5], the ranking kept: a detector "
        "scoring below birth_score",
    )  # fmt: skip
    add_settings(p, "motion.colour_noise=0.2")
    args = p.parse_args(argv)
    if args.scene_seed < 0:
        p.error(f"--scene-seed is {args.scene_seed}, expected a seed >= 0")
    if args.empty < 0:
        p.error(f"--empty is {args.empty}, expected a frame count >= 0")
    if not (np.isfinite(args.upscale) and 0.1 <= args.upscale <= 8):
        p.error(f"--upscale is {args.upscale}, expected a factor in [0.1, 8]")
    config = settings_config(p, args.settings)
    data = data_root(args.data)
    with tee_stdout(args.out / "public_detections.txt"):
        for seed in args.seeds:
            if len(args.seeds) > 1:
                print(f"-- seed {seed}")
            scores = run_all(
                data, config, seed, args.upscale, args.empty, args.low_scores, args.scene_seed
            )
            if scores:
                print(line("pooled", SequenceScores.combine(scores)), flush=True)
    return 0


def run_all(
    data: Path,
    config: TrackerConfig,
    seed: int,
    factor: float = 1.0,
    empty: int = 0,
    low: bool = False,
    scene_seed: int = 0,
) -> list[SequenceScores]:
    """Track every sequence found under `data` and the synthetic scenes; print each row.

    `factor` scales every sequence's frames, detections and truth (``--upscale``); `empty`
    and `low` change the detections (:func:`late_and_low`), and the frames ``1..empty`` are
    not scored. `scene_seed` seeds the synthetic scenes and their detections
    (``--scene-seed``). Returns the scores of every sequence run, in order.
    """
    out: list[SequenceScores] = []

    def report(name: str, gt: F64, rows: F64, scale: float = 1.0) -> None:
        # the values pftrack track writes (2 decimals): pftrack eval of its file scores the same
        rows = as_written(rows)
        gt, rows = gt[gt[:, 0] > empty], rows[rows[:, 0] > empty]
        s = evaluate_sequence(gt, rows, scale=scale * factor)
        out.append(s)
        print(line(name, s), flush=True)

    for src, folder in video_folders(data):
        dets = late_and_low(load_detections(folder / "det.txt", src.scale * factor), empty, low)
        video = FrameSource(folder / src.video)
        source = video if factor == 1 else Resized(video, factor)
        run = track_frames(source, detections=dets, config=config, rng=seed)
        report(src.name, read_mot(folder / "gt.txt"), run.rows, src.scale)
    for name, folder in no_video_folders(data):
        frames = black_frames(folder, factor)
        dets = late_and_low(load_detections(folder / "det.txt", factor), empty, low)
        with blank_frames_expected():
            run = track_frames(frames, detections=dets, config=config, rng=seed)
        report(name + " (black)", read_mot(folder / "gt.txt"), run.rows)
    for kind in BUSY_SCENES:
        scene = make_busy_scene(kind, rng=scene_seed)
        h, w = scene.frames[0].shape[:2]
        dets = noisy_detections(scene.truth, len(scene.frames), h, w, seed=scene_seed)
        dets = scaled(dets, factor)
        dets = late_and_low(dets, empty, low)
        source = scene.frames if factor == 1 else Resized(scene.frames, factor)
        run = track_frames(source, detections=dets, config=config, rng=seed)
        report(kind, scene.truth, run.rows)
    return out


if __name__ == "__main__":
    raise SystemExit(main())
