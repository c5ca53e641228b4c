"""A seeded 1280x720 video of a crowd of 40-60 walkers, with its ground truth (issue 17).

Issue 17's crowd goal ("1280x720 with 40+ objects <= 3.0x decode-only; with ``--render`` <=
4.0x") was measured on PETS09 upscaled to 1280x720, 5-8 people. This script makes the crowd:
``--walkers`` people (default 48) in view on every frame of a paved square seen from above
and in front, their size growing with their foot row (a ground plane: 50 px tall at the top of
the walking area, 140 px at the bottom), each walking left or right at its own speed (PETS09's
pace: 0.4-0.9 % of the width a frame at 7 fps) with a slow drift in depth; whoever leaves
through a side border is replaced at once by a new person (a new id) entering through one, so
the count in view stays at ``--walkers``. Nearer people are drawn over farther ones, so they
occlude each other as in a real crowd. The people are :mod:`pftrack.synthetic`'s walker
sprites (head, striped shirt, legs in a two-phase stride) with a random shirt colour each;
sensor noise as :func:`pftrack.synthetic.make_scene` adds it.

Written to ``OUT/crowd.avi`` (MJPG, the codec of the 1280x720 PETS09 clip of the README's Speed,
so decoding costs are comparable) and ``OUT/gt.txt`` (MOTChallenge, the drawn extent of each
person clipped to the image, occluded parts included), both atomically, frames streamed to
the file (never all held in memory). Same seed, same files. Never commit them.

Usage (from the repository root)::

    python -m experiments.crowd_video --out /tmp/crowd [--walkers 48] [--frames 300] [--seed 0]
    pftrack -q track /tmp/crowd/crowd.avi --out t.txt
    pftrack eval --gt /tmp/crowd/gt.txt --res t.txt
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import experiment_parser, scene_size
from pftrack._typing import F64
from pftrack.io.atomic import atomic_path
from pftrack.io.mot import write_mot
from pftrack.io.opencv_io import opencv_name
from pftrack.synthetic import _SKIN, _TROUSERS, _background, _paste, _sprite

WIDTH, HEIGHT, FPS = 1280, 720, 7.0
WALK_TOP, WALK_BOTTOM = 0.30, 0.99
"""Foot rows of the walking area, as shares of the height (the wall is above it)."""

Frame = NDArray[np.uint8]
Sprite = tuple[NDArray[np.uint8], NDArray[np.bool_]]


@dataclass
class _Person:
    """One person in view: id, position of the feet, velocity, the two stride sprites."""

    id: int
    x: float  # centre x
    foot: float  # foot row (sets the size)
    vx: float
    vfoot: float
    age: int
    looks: tuple[Sprite, Sprite]


def _size_at(foot: float, height: int) -> tuple[int, int]:
    """Body (width, height) of a person whose feet are on row `foot` (the ground plane)."""
    h = max(14, int(round(0.195 * foot)))
    return max(6, int(round(0.38 * h))), h


def _new_person(
    pid: int, gen: np.random.Generator, width: int, height: int, *, inside: bool
) -> _Person:
    """A person at a random depth, inside the frame (`inside`) or just outside a side border."""
    foot = gen.uniform(WALK_TOP, WALK_BOTTOM) * height
    w, h = _size_at(foot, height)
    speed = gen.uniform(0.004, 0.009) * width
    ltr = bool(gen.integers(2))
    if inside:
        x = gen.uniform(0.0, 1.0) * width
    else:
        x = -w / 2.0 + 1.0 if ltr else width + w / 2.0 - 1.0
    hsv = np.array(
        [[[gen.integers(0, 180), gen.integers(90, 230), gen.integers(90, 235)]]], np.uint8
    )
    shirt = tuple(int(c) for c in cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR)[0, 0])
    trousers = _TROUSERS[int(gen.integers(len(_TROUSERS)))]
    skin = _SKIN[int(gen.integers(len(_SKIN)))]
    looks = tuple(
        _sprite(w, h, shirt, trousers, skin, phase, gen)  # type: ignore[arg-type]
        for phase in (0, 1)
    )
    return _Person(
        pid,
        x,
        foot,
        speed if ltr else -speed,
        gen.normal(0.0, 0.0006) * height,
        0,
        looks,  # type: ignore[arg-type]
    )


def crowd_frames(
    n_walkers: int = 48,
    n_frames: int = 300,
    size: tuple[int, int] = (WIDTH, HEIGHT),
    seed: int = 0,
    noise: float = 3.0,
) -> Iterator[tuple[Frame, F64]]:
    """Yield each frame (BGR) of the crowd with its ground-truth rows (M, 10), frame by frame.

    `n_walkers` people are in view on every frame; see the module's description.
    """
    width, height = scene_size("n_walkers", n_walkers, n_frames, size)
    gen = np.random.default_rng(seed)
    bg = _background(width, height, gen)
    people = [_new_person(k + 1, gen, width, height, inside=True) for k in range(n_walkers)]
    next_id = n_walkers + 1
    pad = 16
    pool = gen.normal(0.0, noise, (4, height + pad, width + pad, 3))
    noise_pos = np.clip(pool, 0, 255).astype(np.uint8)
    noise_neg = np.clip(-pool, 0, 255).astype(np.uint8)
    for f in range(1, n_frames + 1):
        frame = bg.copy()
        rows = []
        for p in sorted(people, key=lambda q: (q.foot, q.id)):  # nearer (lower) drawn last
            sprite, mask = p.looks[(p.age // 3) % 2]
            box = _paste(frame, sprite, mask, p.x, p.foot - sprite.shape[0] / 2.0)
            if box is not None:
                rows.append((f, p.id, *box, 1.0, -1.0, -1.0, -1.0))
        j = int(gen.integers(4))
        dx, dy = (int(v) for v in gen.integers(0, pad, 2))
        win = (slice(dy, dy + height), slice(dx, dx + width))
        cv2.add(frame, noise_pos[j][win], dst=frame)
        cv2.subtract(frame, noise_neg[j][win], dst=frame)
        truth = np.asarray(rows, np.float64).reshape(-1, 10)
        yield frame, truth[np.argsort(truth[:, 1], kind="stable")]
        for k, p in enumerate(people):
            p.x += p.vx
            p.foot = float(np.clip(p.foot + p.vfoot, WALK_TOP * height, WALK_BOTTOM * height))
            p.age += 1
            w = p.looks[0][0].shape[1]
            if p.x + w / 2.0 < 0 or p.x - w / 2.0 > width:  # gone: someone else comes in
                people[k] = _new_person(next_id, gen, width, height, inside=False)
                next_id += 1


def write_crowd(
    out: Path, n_walkers: int = 48, n_frames: int = 300, seed: int = 0
) -> tuple[Path, Path]:
    """Write ``out/crowd.avi`` (MJPG) and ``out/gt.txt``, atomically. Returns both paths."""
    out.mkdir(parents=True, exist_ok=True)
    video, gt = out / "crowd.avi", out / "gt.txt"
    truth = []
    with atomic_path(video) as tmp, opencv_name(tmp) as name:
        writer = cv2.VideoWriter(name, cv2.VideoWriter.fourcc(*"MJPG"), FPS, (WIDTH, HEIGHT))
        if not writer.isOpened():
            raise ValueError(f"OpenCV cannot write MJPG video to {video}")
        try:
            for frame, rows in crowd_frames(n_walkers, n_frames, seed=seed):
                writer.write(frame)
                truth.append(rows)
        finally:
            writer.release()
    write_mot(gt, np.concatenate(truth))
    return video, gt


def main(argv: Sequence[str] | None = None) -> None:
    """Write the crowd video and its ground truth to ``--out``."""
    parser = experiment_parser("crowd_video", __doc__)
    parser.add_argument("--walkers", type=int, default=48, help="people in view (default: 48)")
    parser.add_argument("--frames", type=int, default=300, help="frames (default: 300)")
    parser.add_argument("--seed", type=int, default=0, help="seed (default: 0)")
    args = parser.parse_args(argv)
    if args.walkers < 1 or args.frames < 1:
        parser.error("--walkers and --frames must be >= 1")
    video, gt = write_crowd(args.out, args.walkers, args.frames, args.seed)
    print(f"-> {video} ({args.frames} frames of {WIDTH}x{HEIGHT}, {args.walkers} walkers), {gt}")


if __name__ == "__main__":
    main()
