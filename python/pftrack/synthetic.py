"""Seeded synthetic scenes of coloured walkers, with ground truth, for tests and the demo.

A textured static background, people-sized two-tone walkers that enter and leave through the
borders on gently curving paths (two of them cross), a vertical "lamp post" in front of them and
mild per-frame sensor noise. Ground truth is a MOTChallenge array of the walkers' visible extent
(clipped to the image, not to the occluder).

:func:`move_camera` films any scene with a moving camera: :func:`camera_path` gives a smooth
pan, zoom and roll, :func:`warp_frame` and :func:`warp_rows` apply it to frames and MOTChallenge
boxes (real sequences too).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pftrack._check import (
    brief,
    flag,
    generator,
    instance,
    number,
    option,
    real,
    real_array,
    shown,
)
from pftrack._typing import F64, PathLike, RealLike
from pftrack.io.atomic import atomic_path
from pftrack.io.mot import write_mot
from pftrack.io.opencv_io import opencv_name, write_image

__all__ = [
    "BUSY_SCENES",
    "Scene",
    "Walker",
    "camera_path",
    "make_busy_scene",
    "make_scene",
    "move_camera",
    "warp_frame",
    "warp_rows",
]


# Clothing colours (BGR), far apart in hue so colour histograms can tell walkers apart.
_SHIRTS = [
    (40, 40, 200),  # red
    (200, 80, 30),  # blue
    (40, 180, 40),  # green
    (30, 200, 230),  # yellow
    (180, 40, 170),  # purple
    (20, 120, 240),  # orange
    (200, 200, 40),  # cyan
    (230, 230, 230),  # white
]
_TROUSERS = [
    (60, 40, 30),  # dark blue
    (40, 40, 40),  # black
    (70, 110, 150),  # khaki
    (120, 120, 120),  # grey
    (30, 30, 90),  # maroon
]
_SKIN = [(120, 160, 210), (90, 130, 180), (60, 90, 140)]


@dataclasses.dataclass(frozen=True)
class Walker:
    """One walker: id, size and its (centre x, centre y) for every frame it is in the scene.

    Attributes
    ----------
    id : int
        Ground-truth id (from 1).
    width, height : int
        Body size in pixels.
    first_frame : int
        1-based frame of ``centres[0]``.
    centres : (T, 2) ndarray of float64
        Centre of the body at frames ``first_frame .. first_frame + T - 1`` (may be outside).
    shirt, trousers : tuple of int
        BGR clothing colours.
    """

    id: int
    width: int
    height: int
    first_frame: int
    centres: NDArray[np.float64]
    shirt: tuple[int, int, int]
    trousers: tuple[int, int, int]


@dataclasses.dataclass
class Scene:
    """A generated sequence.

    Attributes
    ----------
    frames : list of (H, W, 3) uint8 ndarray
        BGR frames.
    truth : (M, 10) ndarray of float64
        MOTChallenge ground truth: 1-based frames, ids from 1, ``left, top, width, height`` of
        each walker's body clipped to the image (still present while behind the occluder),
        ``conf = 1``, ``x = y = z = -1``.
    background : (H, W, 3) uint8 ndarray
        The empty scene (occluder included, no sensor noise).
    occluder : (4,) tuple of int or None
        ``left, top, width, height`` of the lamp post, drawn in front of walkers.
    walkers : list of Walker
        The walkers' paths.
    fps : float
        Nominal frame rate (for :meth:`write_video`).
    """

    frames: list[NDArray[np.uint8]]
    truth: NDArray[np.float64]
    background: NDArray[np.uint8]
    occluder: tuple[int, int, int, int] | None
    walkers: list[Walker]
    fps: float = 10.0

    @property
    def width(self) -> int:
        """Frame width in pixels."""
        return int(self.background.shape[1])

    @property
    def height(self) -> int:
        """Frame height in pixels."""
        return int(self.background.shape[0])

    def write_video(self, path: PathLike) -> Path:
        """Write the frames as a video file, atomically.

        ``.avi`` gets MJPG, anything else (``.mp4``) mp4v. Returns the path. An odd width or
        height gets one copied column or row at the right or bottom, as
        :class:`pftrack.io.video_writer.VideoWriter` does: the codecs store even sizes only, and
        OpenCV's writer otherwise drops the last column and row without a word (the truth's
        boxes stay where they are either way).

        Raises
        ------
        ValueError
            If OpenCV cannot open a writer for that file type.
        """
        p = Path(path)
        fourcc = cv2.VideoWriter.fourcc(*("MJPG" if p.suffix.lower() == ".avi" else "mp4v"))
        pad_x, pad_y = self.width % 2, self.height % 2
        size = (self.width + pad_x, self.height + pad_y)
        with atomic_path(p) as tmp, opencv_name(tmp) as name:  # any name (pftrack.io.opencv_io)
            writer = cv2.VideoWriter(name, fourcc, self.fps, size)
            if not writer.isOpened():
                raise ValueError(f"write_video: OpenCV cannot write {p.suffix!r} video to {p}")
            try:
                for frame in self.frames:
                    if pad_x or pad_y:
                        frame = np.pad(frame, ((0, pad_y), (0, pad_x), (0, 0)), mode="edge")
                    writer.write(frame)
            finally:
                writer.release()
        return p

    def write_images(self, folder: PathLike, *, ext: str = ".png") -> Path:
        """Write one image per frame (``000001.png`` ...) into `folder` (created if needed).

        Each file is written atomically. Returns the folder.
        """
        d = Path(folder)
        d.mkdir(parents=True, exist_ok=True)
        for k, frame in enumerate(self.frames, start=1):
            try:
                write_image(d / f"{k:06d}{ext}", frame)
            except ValueError:
                raise ValueError(f"write_images: OpenCV cannot write {ext!r} images") from None
        return d

    def write_truth(self, path: PathLike) -> Path:
        """Write :attr:`truth` as a MOTChallenge ``gt.txt`` (atomically). Returns the path."""
        write_mot(path, self.truth)
        return Path(path)


def _background(width: int, height: int, rng: np.random.Generator) -> NDArray[np.uint8]:
    """Paved square: gradient, blotchy low-frequency texture, paving joints, a wall and a bench."""
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    base = np.array([105, 120, 125], np.float32)  # greyish stone (BGR)
    grad = (0.35 * (yy / height) - 0.15 * (xx / width))[..., None] * 60.0
    coarse = rng.normal(0.0, 14.0, (height // 24 + 2, width // 24 + 2, 1)).astype(np.float32)
    blotch = cv2.resize(coarse, (width, height), interpolation=cv2.INTER_CUBIC)[..., None]
    fine = rng.normal(0.0, 5.0, (height, width, 1)).astype(np.float32)
    img = base + grad + blotch + fine
    # Paving joints, denser towards the top (perspective).
    for k in range(1, 14):
        y = int(height * (k / 14) ** 1.6)
        img[y : y + 1] -= 18
    for x in range(0, width, 40):
        img[:, x : x + 1] -= 10
    # A wall across the top with windows, and a bench.
    wall_h = max(8, height // 7)
    img[:wall_h] = np.array([70, 85, 150], np.float32) + fine[:wall_h] * 1.5
    for x in range(10, width - 20, 45):
        img[wall_h // 4 : wall_h * 3 // 4, x : x + 20] = (60, 50, 40)
    bx, by = int(0.7 * width), int(0.45 * height)
    img[by : by + 6, bx : bx + 60] = (40, 70, 100)
    out: NDArray[np.uint8] = np.clip(img, 0, 255).astype(np.uint8)
    return out


def _sprite(
    width: int,
    height: int,
    shirt: tuple[int, int, int],
    trousers: tuple[int, int, int],
    skin: tuple[int, int, int],
    phase: int,
    rng: np.random.Generator,
) -> tuple[NDArray[np.uint8], NDArray[np.bool_]]:
    """Draw a walker: (height, width) BGR image and mask of head, torso and legs in a stride."""
    img = np.zeros((height, width, 3), np.uint8)
    mask = np.zeros((height, width), np.uint8)
    head_h = max(6, height // 7)
    torso_b = int(height * 0.55)
    cx = width // 2
    # head
    cv2.ellipse(img, (cx, head_h // 2), (max(3, width // 5), head_h // 2), 0, 0, 360, skin, -1)
    cv2.ellipse(mask, (cx, head_h // 2), (max(3, width // 5), head_h // 2), 0, 0, 360, 1, -1)
    # torso (an ellipse-topped rectangle)
    cv2.rectangle(img, (0, head_h + 2), (width - 1, torso_b), shirt, -1)
    cv2.rectangle(mask, (0, head_h + 2), (width - 1, torso_b), 1, -1)
    # legs: stride alternates between two phases
    leg_w = max(3, width // 3)
    spread = (width // 6) * (1 if phase else -1)
    for lx in (cx - leg_w - 1 + spread, cx + 1 - spread):
        lx = int(np.clip(lx, 0, width - leg_w))
        cv2.rectangle(img, (lx, torso_b), (lx + leg_w - 1, height - 1), trousers, -1)
        cv2.rectangle(mask, (lx, torso_b), (lx + leg_w - 1, height - 1), 1, -1)
    # cloth texture: stripes on the shirt and per-pixel noise
    stripes = ((np.arange(height)[:, None] // 4) % 2 * 14 - 7).astype(np.int16)
    tex = rng.normal(0, 6, (height, width, 1)).astype(np.int16)
    out = img.astype(np.int16) + tex
    out[head_h + 2 : torso_b] += stripes[head_h + 2 : torso_b, :, None]
    img = np.clip(out, 0, 255).astype(np.uint8)
    return img, mask.astype(bool)


def _path(
    rng: np.random.Generator,
    width: int,
    height: int,
    w: int,
    h: int,
    n_frames: int,
    *,
    left_to_right: bool,
    start_inside: bool,
    y_band: tuple[float, float],
    start_frame: int,
    speed_range: tuple[float, float],
) -> tuple[int, NDArray[np.float64]]:
    """Quadratic Bézier from one side border to the other, walked at `speed_range` px a frame."""
    y0 = rng.uniform(*y_band) * height
    y1 = float(np.clip(y0 + rng.normal(0, 0.15 * height), 0.3 * height, 0.85 * height))
    xs, xe = -w / 2.0 - 1.0, width + w / 2.0 + 1.0
    if not left_to_right:
        xs, xe = xe, xs
    p0 = np.array([xs, y0])
    p2 = np.array([xe, y1])
    if start_inside:
        p0 = np.array([rng.uniform(0.15, 0.3) * width, y0])
        if not left_to_right:
            p0[0] = width - p0[0]
    p1 = 0.5 * (p0 + p2) + np.array([0.0, rng.normal(0, 0.12 * height)])
    length = float(np.linalg.norm(p1 - p0) + np.linalg.norm(p2 - p1))
    speed = rng.uniform(*speed_range) * width / 480.0
    steps = max(2, int(length / speed))
    t = np.linspace(0.0, 1.0, steps)[:, None]
    pts = (1 - t) ** 2 * p0 + 2 * (1 - t) * t * p1 + t**2 * p2
    pts += rng.normal(0, 0.3, pts.shape)  # gait sway
    return start_frame, pts[: max(1, n_frames - start_frame + 1)]


def _paste(
    frame: NDArray[np.uint8],
    sprite: NDArray[np.uint8],
    silhouette: NDArray[np.bool_],
    cx: float,
    cy: float,
) -> tuple[int, int, int, int] | None:
    """Draw `sprite`'s `silhouette` pixels centred at (cx, cy), clipped to the frame.

    Returns the drawn box ``left, top, w, h`` inside the frame, or None when nothing is in it.
    """
    h, w = silhouette.shape
    x0, y0 = int(round(cx - w / 2.0)), int(round(cy - h / 2.0))
    xa, ya = max(x0, 0), max(y0, 0)
    xb, yb = min(x0 + w, frame.shape[1]), min(y0 + h, frame.shape[0])
    if xb <= xa or yb <= ya:
        return None
    sub = silhouette[ya - y0 : yb - y0, xa - x0 : xb - x0]
    frame[ya:yb, xa:xb][sub] = sprite[ya - y0 : yb - y0, xa - x0 : xb - x0][sub]
    return xa, ya, xb - xa, yb - ya


MAX_SCENE_BYTES = 2**33
"""Largest scene :func:`make_scene` and :func:`make_busy_scene` make: 8 GiB of frames."""


def _check_scene_args(
    fn: str, n_frames: int, width: int, height: int, noise: float, fps: RealLike
) -> float:
    """The frame count, size, noise level and rate `make_scene` and `make_busy_scene` share.

    Returns `fps` as a float (a Fraction too, as PyAV gives rates; was stored as given, and a
    scene with a Fraction, text or 0 failed only when saved).
    """
    for name, v, lo in (("n_frames", n_frames, 1), ("width", width, 64), ("height", height, 64)):
        if not isinstance(v, (int, np.integer)) or isinstance(v, bool):
            raise TypeError(f"{fn}: {name} is {brief(v)}, expected an integer >= {lo}")
        if v < lo:
            raise ValueError(f"{fn}: {name} is {brief(v)}, expected an integer >= {lo}")
    size = int(n_frames) * int(width) * int(height) * 3  # the frames are held in memory
    if size > MAX_SCENE_BYTES:
        raise ValueError(
            f"{fn}: {n_frames} frames of {width}x{height} are {size / 2**30:.3g} GiB of BGR "
            f"pixels, held in memory; at most {MAX_SCENE_BYTES // 2**30} GiB (fewer or smaller "
            "frames)"
        )
    # was: None or text failed in NumPy ("ufunc 'isfinite' not supported"), True was noise 1
    if not (np.isfinite(number(noise, f"{fn}: noise", finite=False)) and noise >= 0):
        raise ValueError(f"{fn}: noise is {noise}, expected a finite value >= 0")
    rate = real(fps, f"{fn}: fps", finite=False)
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"{fn}: fps is {fps}, expected a finite value > 0")
    return rate


def make_scene(
    n_frames: int = 120,
    width: int = 480,
    height: int = 360,
    n_walkers: int = 5,
    rng: np.random.Generator | int | None = 0,
    occluder: bool = True,
    *,
    noise: float = 3.0,
    fps: RealLike = 10.0,
) -> Scene:
    """Generate a seeded scene of walkers on a textured background.

    Parameters
    ----------
    n_frames : int
        Number of frames (>= 1; all of them, 8 GiB at most, are held in memory).
    width, height : int
        Frame size (>= 64 x 64).
    n_walkers : int
        Number of walkers (1 to 40). Walker 1 is inside the image from frame 1; walkers 1 and 2
        walk in opposite directions at the same height and time, so their boxes cross; walkers
        3, 4, ... enter through the left or right border at random times.
    rng : numpy.random.Generator, int or None
        Seed or generator; the same seed gives the same scene.
    occluder : bool
        Draw a vertical lamp post at 40 % of the width, in front of the walkers.
    noise : float
        Standard deviation of the per-frame sensor noise in grey levels (0 for none).
    fps : float
        Nominal frame rate stored in the scene.

    Returns
    -------
    Scene
    """
    fps = _check_scene_args("make_scene", n_frames, width, height, noise, fps)
    if not isinstance(n_walkers, (int, np.integer)) or isinstance(n_walkers, bool):
        # was: True taken for 1 walker; 2.0 a ValueError, as n_frames=2.0 is a TypeError
        raise TypeError(
            f"make_scene: n_walkers is {brief(n_walkers)}, expected an integer in 1..40"
        )
    if not 1 <= n_walkers <= 40:
        raise ValueError(
            f"make_scene: n_walkers is {brief(n_walkers)}, expected an integer in 1..40"
        )
    occluder = flag(occluder, "make_scene: occluder")  # was: any value taken for its truth
    gen = generator(rng, "make_scene: rng")
    bg = _background(width, height, gen)
    size_scale = height / 360.0

    occ: tuple[int, int, int, int] | None = None
    if occluder:
        ow = max(4, int(round(0.025 * width)))
        ox = int(0.4 * width)
        oy = int(0.08 * height)
        occ = (ox, oy, ow, height - oy)
        cv2.rectangle(bg, (ox, oy), (ox + ow - 1, height - 1), (45, 50, 55), -1)
        cv2.line(bg, (ox + 1, oy), (ox + 1, height - 1), (90, 95, 100), 1)  # highlight
        cv2.rectangle(bg, (ox - 6, oy - 8), (ox + ow + 5, oy), (30, 35, 40), -1)  # lamp head

    walkers: list[Walker] = []
    sprites: list[tuple[tuple[NDArray[np.uint8], NDArray[np.bool_]], ...]] = []
    shirt_order = gen.permutation(len(_SHIRTS))
    for k in range(n_walkers):
        w = int(round(gen.uniform(20, 40) * size_scale))
        h = int(round(gen.uniform(50, 100) * size_scale))
        w, h = max(w, 6), max(h, 14)
        if k == 0:
            start, ltr, inside, band = 1, True, True, (0.5, 0.6)
        elif k == 1:
            # Meets walker 1 near the middle: starts at the right border at the same time.
            start, ltr, inside, band = 1, False, False, (0.5, 0.6)
        else:
            start = int(gen.integers(1, max(2, n_frames * 2 // 3)))
            ltr, inside, band = bool(gen.integers(2)), False, (0.35, 0.75)
        speeds = (4.0, 5.0) if k == 0 else (2.5, 4.5)  # walker 1 leaves within ~100 frames
        first, centres = _path(
            gen,
            width,
            height,
            w,
            h,
            n_frames,
            left_to_right=ltr,
            start_inside=inside,
            y_band=band,
            start_frame=start,
            speed_range=speeds,
        )
        shirt = _SHIRTS[int(shirt_order[k % len(_SHIRTS)])]
        trousers = _TROUSERS[int(gen.integers(len(_TROUSERS)))]
        skin = _SKIN[int(gen.integers(len(_SKIN)))]
        walkers.append(Walker(k + 1, w, h, first, centres, shirt, trousers))
        sprites.append(tuple(_sprite(w, h, shirt, trousers, skin, ph, gen) for ph in (0, 1)))

    # Sensor noise: a pool of noise images, each frame a random window of one of them.
    pad = 16
    if noise > 0:
        pool = gen.normal(0.0, noise, (4, height + pad, width + pad, 3))
        noise_pos = np.clip(pool, 0, 255).astype(np.uint8)
        noise_neg = np.clip(-pool, 0, 255).astype(np.uint8)

    frames: list[NDArray[np.uint8]] = []
    truth: list[tuple[float, ...]] = []
    for f in range(1, n_frames + 1):
        frame = bg.copy()
        visible = []
        for k, wk in enumerate(walkers):
            i = f - wk.first_frame
            if 0 <= i < len(wk.centres):
                cx, cy = wk.centres[i]
                visible.append((cy + wk.height / 2.0, k, cx, cy))
        # Nearer (lower) walkers are drawn last, in front.
        for _, k, cx, cy in sorted(visible):
            wk = walkers[k]
            box = _paste(frame, *sprites[k][((f - wk.first_frame) // 3) % 2], cx, cy)
            if box is not None:
                truth.append((f, wk.id, *box, 1.0, -1.0, -1.0, -1.0))
        if occ is not None:  # the post is in front of everyone
            ox, oy, ow, oh = occ
            frame[oy : oy + oh, ox : ox + ow] = bg[oy : oy + oh, ox : ox + ow]
        if noise > 0:
            j = int(gen.integers(4))
            dx, dy = (int(v) for v in gen.integers(0, pad, 2))
            win = (slice(dy, dy + height), slice(dx, dx + width))
            cv2.add(frame, noise_pos[j][win], dst=frame)
            cv2.subtract(frame, noise_neg[j][win], dst=frame)
        frames.append(frame)

    t = np.asarray(truth, dtype=np.float64).reshape(-1, 10)
    if len(t):
        t = t[np.lexsort((t[:, 1], t[:, 0]))]
    return Scene(frames=frames, truth=t, background=bg, occluder=occ, walkers=walkers, fps=fps)


def camera_path(
    n_frames: int,
    size: tuple[int, int],
    *,
    zoom: float = 1.35,
    zoom_swing: float = 0.1,
    pan: tuple[float, float] = (0.06, 0.04),
    roll: float = 3.0,
    period: float = 120.0,
) -> NDArray[np.float64]:
    """A smooth moving-camera path: one source-to-image affine per frame.

    Each frame shows a window of the source, zoomed in by ``zoom ± zoom_swing``, panned by up
    to ``pan`` (shares of the width and height) from the centre and rolled by up to ``roll``
    degrees, every part a sinusoid of its own period (``period``, 1.3, 1.7 and 2.1 times it) and
    phase. The defaults keep the window inside the source (no border). With ``zoom_swing``,
    ``pan`` and ``roll`` all 0 the camera is still (a fixed crop).

    Parameters
    ----------
    n_frames : int
        Frames (>= 1).
    size : (height, width)
        Source and image size.
    zoom, zoom_swing, pan, roll, period : float
        As above.

    Returns
    -------
    (n_frames, 2, 3) ndarray
        ``A_t`` maps a source pixel to frame t's pixel (``cv2.warpAffine``'s convention).
    """
    if not isinstance(n_frames, (int, np.integer)) or n_frames < 1:
        raise ValueError(f"camera_path: n_frames is {brief(n_frames)}, expected an integer >= 1")
    zoom, zoom_swing, period = (
        real(v, f"camera_path: {name}", finite=False)
        for v, name in ((zoom, "zoom"), (zoom_swing, "zoom_swing"), (period, "period"))
    )
    if not (zoom - zoom_swing > 0 and period > 0):
        raise ValueError("camera_path: need zoom - zoom_swing > 0 and period > 0")
    h, w = size
    t = np.arange(n_frames, dtype=np.float64)
    z = zoom + zoom_swing * np.sin(2 * np.pi * t / (1.3 * period) + 0.5)
    sx = pan[0] * w * np.sin(2 * np.pi * t / period)
    sy = pan[1] * h * np.sin(2 * np.pi * t / (1.7 * period) + 1.0)
    th = np.deg2rad(roll) * np.sin(2 * np.pi * t / (2.1 * period) + 2.0)
    c = np.array([w / 2, h / 2])
    out = np.empty((n_frames, 2, 3))
    for k in range(n_frames):
        # u = c + z R(-theta) (x - c - shift)
        cos, sin = np.cos(th[k]), np.sin(th[k])
        lin = z[k] * np.array([[cos, sin], [-sin, cos]])
        out[k, :, :2] = lin
        out[k, :, 2] = c - lin @ (c + np.array([sx[k], sy[k]]))
    return out


def _affines(value: ArrayLike, what: str, shape: tuple[int, ...]) -> NDArray[np.float64]:
    """`value` as a finite float64 array of `shape` (-1: any length), or TypeError/ValueError."""
    a = real_array(value, what, booleans=False)  # TypeError: not numbers; ValueError: ragged
    if a.ndim != len(shape) or any(n not in (-1, m) for n, m in zip(shape, a.shape, strict=True)):
        expected = ", ".join("T" if n == -1 else str(n) for n in shape)
        raise ValueError(f"{what} has shape {a.shape}, expected ({expected})")
    if not np.isfinite(a).all():
        raise ValueError(f"{what} has a value that is NaN or inf")
    return a


def warp_frame(frame: NDArray[np.uint8], affine: NDArray[np.float64]) -> NDArray[np.uint8]:
    """Frame `frame` seen through `affine` (source to image, same size; bilinear).

    Raises
    ------
    TypeError
        If `frame` is not an array (was: an AttributeError), or `affine` not one of numbers.
    ValueError
        If `frame` is not an (H, W) or (H, W, C) image, or `affine` not a finite (2, 3) matrix
        (were: OpenCV's assertion, in several lines).
    """
    if not isinstance(frame, np.ndarray):
        raise TypeError(f"warp_frame: frame must be an (H, W, 3) array, got {shown(frame)}")
    if frame.ndim not in (2, 3) or frame.shape[0] == 0 or frame.shape[1] == 0:
        raise ValueError(f"warp_frame: frame has shape {frame.shape}, expected (H, W, 3)")
    affine = _affines(affine, "warp_frame: affine", (2, 3))
    h, w = frame.shape[:2]
    out = cv2.warpAffine(
        frame, affine, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
    )
    return np.asarray(out, dtype=np.uint8)


def warp_rows(
    rows: NDArray[np.float64],
    affines: NDArray[np.float64],
    size: tuple[int, int],
    *,
    min_visible: float = 0.5,
) -> NDArray[np.float64]:
    """MOTChallenge rows (ground truth or detections) moved with the camera.

    Each box's centre goes through its frame's affine and its size is multiplied by the
    affine's zoom (``sqrt(det)``; the box stays axis-aligned); it is then clipped to the image,
    and dropped when less than `min_visible` of it remains inside. Frames without an affine
    (beyond ``len(affines)``) are dropped.

    Parameters
    ----------
    rows : (M, >=6) ndarray
        1-based frame, id, left, top, width, height, ... in source pixels.
    affines : (T, 2, 3) ndarray
        From :func:`camera_path`.
    size : (height, width)
        Image size.
    min_visible : float
        Share of a box that must stay inside the image.
    """
    if not isinstance(rows, (np.ndarray, list, tuple)):
        raise TypeError(f"warp_rows: rows must be an (M, 10) array, got {shown(rows)}")
    shape = np.shape(rows)
    if len(shape) not in (1, 2) or shape[-1] < 6:  # was: NumPy's IndexError
        raise ValueError(f"warp_rows: rows has shape {shape}, expected (M, 6..10)")
    affines = _affines(affines, "warp_rows: affines", (-1, 2, 3))
    if not isinstance(size, (tuple, list)) or len(size) != 2:
        raise TypeError(f"warp_rows: size must be (height, width), got {shown(size)}")
    r = np.array(rows, dtype=np.float64, copy=True).reshape(-1, shape[-1])
    f = r[:, 0].astype(np.int64) - 1
    r = r[(f >= 0) & (f < len(affines))]
    a = affines[r[:, 0].astype(np.int64) - 1]
    zoom = np.sqrt(np.abs(np.linalg.det(a[:, :, :2])))
    centre = r[:, 2:4] + r[:, 4:6] / 2
    centre = np.einsum("kij,kj->ki", a[:, :, :2], centre) + a[:, :, 2]
    wh = r[:, 4:6] * zoom[:, None]
    x0, y0 = np.maximum(centre - wh / 2, 0.0).T
    x1 = np.minimum(centre[:, 0] + wh[:, 0] / 2, size[1])
    y1 = np.minimum(centre[:, 1] + wh[:, 1] / 2, size[0])
    vis = np.clip(x1 - x0, 0, None) * np.clip(y1 - y0, 0, None)
    keep = (vis >= min_visible * wh[:, 0] * wh[:, 1]) & (x1 - x0 >= 2) & (y1 - y0 >= 2)
    r[:, 2], r[:, 3], r[:, 4], r[:, 5] = x0, y0, x1 - x0, y1 - y0
    out: NDArray[np.float64] = r[keep]
    return out


def move_camera(scene: Scene, **path: Any) -> Scene:
    """`scene` filmed by a moving camera (:func:`camera_path` with the `path` settings).

    Frames and ground truth are warped; the background is the first frame's view and the
    occluder is dropped (it moves with the view).
    """
    instance(scene, "move_camera: scene", Scene)  # was: an AttributeError
    affines = camera_path(len(scene.frames), (scene.height, scene.width), **path)
    return Scene(
        frames=[warp_frame(f, a) for f, a in zip(scene.frames, affines, strict=True)],
        truth=warp_rows(scene.truth, affines, (scene.height, scene.width)),
        background=warp_frame(scene.background, affines[0]),
        occluder=None,
        walkers=scene.walkers,
        fps=scene.fps,
    )


BUSY_SCENES = ("present", "groups", "overhead")


def make_busy_scene(
    kind: str,
    n_frames: int = 100,
    width: int = 480,
    height: int = 360,
    rng: np.random.Generator | int | None = 0,
    *,
    noise: float = 3.0,
    fps: RealLike = 10.0,
) -> Scene:
    """A seeded scene reproducing one failure of background subtraction on busy scenes.

    Parameters
    ----------
    kind : {"present", "groups", "overhead"}
        ``"present"``: six people, close to the camera and in perspective (box size grows
        with the foot row), all in view from frame 1; each stands still for 15 to 50 frames,
        then walks off through the nearer side border (ghosts of a background learnt from the
        first frames). ``"groups"``: three groups of two or three people walking side by side
        (their silhouettes touch: one blob a group), at different depths, entering through
        the borders at staggered times. ``"overhead"``: a grey (R = G = B) top-down view of
        14 people as ellipses of one size whatever the row (no tall person shape); half
        stand for 20 to 60 frames first; all walk in straight lines in random directions.
    n_frames : int
        Number of frames (>= 1; all of them, 8 GiB at most, are held in memory).
    width, height : int
        Frame size (>= 64 x 64).
    rng : numpy.random.Generator, int or None
        Seed or generator; the same seed gives the same scene.
    noise : float
        Standard deviation of the per-frame sensor noise in grey levels (0 for none).
    fps : float
        Nominal frame rate stored in the scene.

    Returns
    -------
    Scene
        With ``occluder=None``; truth boxes are the people's visible extent clipped to the
        image.
    """
    option(kind, "make_busy_scene: kind", BUSY_SCENES)
    if kind not in BUSY_SCENES:
        raise ValueError(f"make_busy_scene: kind is {kind!r}, expected one of {BUSY_SCENES}")
    fps = _check_scene_args("make_busy_scene", n_frames, width, height, noise, fps)
    gen = generator(rng, "make_busy_scene: rng")
    bg = _background(width, height, gen)
    grey = kind == "overhead"
    if grey:
        bg = np.repeat(cv2.cvtColor(bg, cv2.COLOR_BGR2GRAY)[..., None], 3, axis=2)
    s = width / 480.0  # speeds scale with the frame

    def size_at(foot: float) -> tuple[int, int]:
        # ground plane: height linear in the foot row, zero at the horizon (0.2 H)
        h = 1.1 * (foot - 0.2 * height)
        return max(6, int(round(0.36 * h))), max(14, int(round(h)))

    def stand_then_walk(x: float, foot: float, w: int, h: int, stand: int, vx: float) -> F64:
        t = np.arange(n_frames, dtype=np.float64)
        cx = x + vx * np.maximum(t - stand, 0.0)
        c = np.column_stack([cx, np.full(n_frames, foot - h / 2.0)])
        inside = (cx + w / 2.0 > 0) & (cx - w / 2.0 < width)
        return c[: int(np.flatnonzero(inside)[-1]) + 1] if inside.any() else c[:1]

    # (first frame, centres, width, height, sprite phases)
    people: list[tuple[int, F64, int, int, tuple[tuple[NDArray[np.uint8], NDArray[np.bool_]], ...]]]
    people = []
    shirts = gen.permutation(len(_SHIRTS))
    if kind == "present":
        for k in range(6):
            foot = gen.uniform(0.6, 0.98) * height
            w, h = size_at(foot)
            x = (k + 0.5) / 6 * width + gen.uniform(-0.03, 0.03) * width
            vx = gen.uniform(3.0, 5.0) * s * (-1.0 if x < width / 2 else 1.0)
            centres = stand_then_walk(x, foot, w, h, int(gen.integers(15, 51)), vx)
            people.append((1, centres, w, h, _looks(w, h, shirts[k % len(shirts)], gen)))
    elif kind == "groups":
        for g in range(3):
            foot = gen.uniform(0.55, 0.95) * height
            members = int(gen.integers(2, 4))
            ltr = g % 2 == 0
            vx = gen.uniform(2.5, 4.0) * s * (1.0 if ltr else -1.0)
            start = 1 + g * max(1, n_frames // 6)
            w, h = size_at(foot)
            for m in range(members):
                # side by side, shoulders touching (0.85 w apart), feet on one row
                x0 = (
                    (-w / 2.0 - 1.0 - m * 0.85 * w) if ltr else (width + w / 2.0 + 1 + m * 0.85 * w)
                )
                x0 += vx  # first frame one step in
                centres = stand_then_walk(x0, foot + gen.uniform(-2, 2), w, h, 0, vx)
                look = _looks(w, h, shirts[(3 * g + m) % len(shirts)], gen)
                people.append((start, centres[: max(1, n_frames - start + 1)], w, h, look))
    else:
        d = max(8, int(round(0.075 * height)))
        for k in range(14):
            w, h = d + int(gen.integers(-1, 2)), int(round(d * 1.15))
            level = int(gen.choice([gen.integers(20, 70), gen.integers(190, 240)]))
            angle = gen.uniform(0, 2 * np.pi)
            speed = gen.uniform(2.0, 3.5) * s
            stand = int(gen.integers(20, 61)) if k % 2 == 0 else 0
            p = np.array([gen.uniform(0.1, 0.9) * width, gen.uniform(0.1, 0.9) * height])
            t = np.maximum(np.arange(n_frames, dtype=np.float64) - stand, 0.0)[:, None]
            c = p + t * speed * np.array([np.cos(angle), np.sin(angle)])
            inside = (np.abs(c[:, 0] - width / 2) < width / 2 + w / 2) & (
                np.abs(c[:, 1] - height / 2) < height / 2 + h / 2
            )
            c = c[: int(np.flatnonzero(~inside)[0])] if (~inside).any() else c
            img = np.zeros((h, w, 3), np.uint8)
            mask = np.zeros((h, w), np.uint8)
            cv2.ellipse(mask, (w // 2, h // 2), (w // 2 - 1, h // 2 - 1), 0, 0, 360, 1, -1)
            tex = gen.normal(0, 6, (h, w, 1))
            img[:] = np.clip(level + tex, 0, 255).astype(np.uint8)
            people.append((1, c, w, h, ((img, mask.astype(bool)),) * 2))

    pad = 16
    pool = gen.normal(0.0, noise, (4, height + pad, width + pad, 1 if grey else 3))
    frames: list[NDArray[np.uint8]] = []
    truth: list[tuple[float, ...]] = []
    for f in range(1, n_frames + 1):
        frame = bg.copy()
        visible = []
        for k, (first, centres, _w, h, _) in enumerate(people):
            i = f - first
            if 0 <= i < len(centres):
                visible.append((centres[i][1] + h / 2.0, k, i))
        for _, k, i in sorted(visible):  # nearer (lower) people in front
            _, centres, _, _, look = people[k]
            box = _paste(frame, *look[(i // 3) % 2], centres[i][0], centres[i][1])
            if box is not None:
                truth.append((f, k + 1, *box, 1.0, -1.0, -1.0, -1.0))
        if noise > 0:
            j = int(gen.integers(4))
            dx, dy = (int(v) for v in gen.integers(0, pad, 2))
            n = pool[j][dy : dy + height, dx : dx + width]
            frame = np.clip(frame + n, 0, 255).astype(np.uint8)
        frames.append(frame)
    t = np.asarray(truth, dtype=np.float64).reshape(-1, 10)
    if len(t):
        t = t[np.lexsort((t[:, 1], t[:, 0]))]
    walkers = [
        Walker(k + 1, w, h, first, centres, (0, 0, 0), (0, 0, 0))
        for k, (first, centres, w, h, _) in enumerate(people)
    ]
    return Scene(frames=frames, truth=t, background=bg, occluder=None, walkers=walkers, fps=fps)


def _looks(
    w: int, h: int, shirt_index: int, gen: np.random.Generator
) -> tuple[tuple[NDArray[np.uint8], NDArray[np.bool_]], ...]:
    """The two stride phases of a side-view person of size (h, w)."""
    shirt = _SHIRTS[int(shirt_index)]
    trousers = _TROUSERS[int(gen.integers(len(_TROUSERS)))]
    skin = _SKIN[int(gen.integers(len(_SKIN)))]
    return tuple(_sprite(w, h, shirt, trousers, skin, ph, gen) for ph in (0, 1))
