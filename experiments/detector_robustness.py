"""The built-in detector on footage it was not tuned on: grey, slowly darkening, cropped.

Each case is one sequence in one variant, tracked by ``pftrack.tracking.track_frames`` (the
built-in detector unless ``--detector``, every default, ``--bootstrap`` as given;
``TrackerConfig.hold_frames`` from ``--hold-frames``, 0 as by default) and scored with
``pftrack.eval.evaluate_sequence`` (HOTA, MOTA, IDF1, FP, FN, IDSW). Variants:

``ident``  the frames as they are (real sequences: re-encoded as JPEG, quality 95)
``grey``   every pixel set to its grey level (B = G = R, ``cv2.COLOR_BGR2GRAY``)
``ramp``   brightness multiplied by ``1 - 0.6 k / (N - 1)`` at the k-th of N frames (to 40 %)
``step``   brightness multiplied by 1.4 from the frame a third of the way in (clipped at 255):
           a light switched on, the second user trial's clip
``crop``   the bottom-right 240x240 pixels of a real video; ground-truth boxes clipped to it,
           kept when at least half their area is inside (synthetic scenes: skipped)

Sequences: ``pets`` (PETS09-S2L1) and ``tud`` (TUD-Campus) from ``--data``, written as JPEG
image folders into ``OUT/frames/`` (reused by later runs; nothing is written into the
repository), and the synthetic scenes made in memory: ``walkers``
(``pftrack.synthetic.make_scene``, seed 0) and ``present``, ``groups``, ``overhead``
(``make_busy_scene``, seed 0). One line is printed per case; the table is also written to
``OUT/robustness.txt``.

Usage (from the repository root)::

    python -m experiments.detector_robustness [--data ../shared/data]
        [--sequences pets,tud,walkers,present,groups,overhead] [--variants ident,grey,ramp]
        [--detector paper] [--bootstrap auto] [--seed 0] [--hold-frames 0]
        [--grey-t-min T] [--grey-shadow-lo LO] [--grey-texture C] [--grey-texture-window W]
        [--grey-texture-erode E] [--out out/detector_robustness]

``--grey-t-min`` and ``--grey-shadow-lo`` set ``PaperConfig.grey_t_min`` and
``grey_shadow_lo`` (the built-in detector's threshold bound and shadow bound on grey video),
``--grey-texture*`` its ``grey_texture``, ``grey_texture_window``, ``grey_texture_erode``
(the texture cue on grey video, off by default); colour video is not affected.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import (
    PETS,
    TUD,
    Source,
    data_root,
    experiment_parser,
    frame_truth,
    tee_stdout,
)
from pftrack._typing import F64
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import as_written
from pftrack.io.opencv_io import write_image
from pftrack.io.video import FrameSource
from pftrack.synthetic import BUSY_SCENES, make_busy_scene, make_scene

REAL: dict[str, Source] = {"pets": PETS, "tud": TUD}
SYNTHETIC = ("walkers", *BUSY_SCENES)
VARIANTS = ("ident", "grey", "ramp", "step", "crop")
STEP_GAIN = 1.4  # the ``step`` variant's brightening
CROP = 240  # side of the bottom-right crop, in video pixels

Frame = NDArray[np.uint8]


def grey(frame: Frame) -> Frame:
    """The frame's grey level in all three channels."""
    g = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    return np.asarray(cv2.cvtColor(g, cv2.COLOR_GRAY2BGR), np.uint8)


def ramp(frame: Frame, k: int, n: int, floor: float = 0.4) -> Frame:
    """The k-th (0-based) of `n` frames darkened linearly: gain 1 at the first, `floor` at the
    last (the trial's ``variants.py``: float32 product, clipped, truncated)."""
    gain = 1.0 - (1.0 - floor) * k / max(n - 1, 1)
    return np.clip(frame.astype(np.float32) * gain, 0, 255).astype(np.uint8)


def step(frame: Frame, k: int, n: int, gain: float = STEP_GAIN) -> Frame:
    """The k-th (0-based) of `n` frames, brightened by `gain` from frame ``n // 3`` on."""
    if k < n // 3:
        return frame
    return np.clip(frame.astype(np.float32) * gain, 0, 255).astype(np.uint8)


def crop_truth(gt: F64, x0: int, y0: int, w: int, h: int, keep: float = 0.5) -> F64:
    """Ground-truth rows (in frame pixels) clipped to the window ``[x0, x0+w) x [y0, y0+h)``,
    shifted to its origin; rows with less than `keep` of their area inside are dropped."""
    r = gt.copy()
    x1 = np.maximum(r[:, 2], x0)
    y1 = np.maximum(r[:, 3], y0)
    x2 = np.minimum(r[:, 2] + r[:, 4], x0 + w)
    y2 = np.minimum(r[:, 3] + r[:, 5], y0 + h)
    ok = (x2 > x1) & (y2 > y1) & ((x2 - x1) * (y2 - y1) >= keep * r[:, 4] * r[:, 5])
    r[:, 2], r[:, 3], r[:, 4], r[:, 5] = x1 - x0, y1 - y0, x2 - x1, y2 - y1
    return r[ok]


def transform(frames: Sequence[Frame], variant: str) -> list[Frame]:
    """The frames of `variant` (see the module's docstring)."""
    n = len(frames)
    if variant == "ident":
        return list(frames)
    if variant == "grey":
        return [grey(f) for f in frames]
    if variant == "ramp":
        return [ramp(f, k, n) for k, f in enumerate(frames)]
    if variant == "step":
        return [step(f, k, n) for k, f in enumerate(frames)]
    if variant == "crop":
        return [np.ascontiguousarray(f[-CROP:, -CROP:]) for f in frames]
    raise ValueError(f"unknown variant {variant!r}")


def real_case(name: str, variant: str, data: Path, out: Path) -> tuple[Path, F64] | None:
    """The JPEG image folder of a real sequence's variant (written once, then reused) and its
    ground truth in the folder's pixels; None without the data."""
    src = REAL[name]
    seq = data / src.name
    if not (seq / src.video).is_file():
        return None
    gt = frame_truth(src, data)
    folder = out / "frames" / f"{name}_{variant}" / "img1"
    frames: list[Frame] | None = None
    if variant == "crop" or not folder.is_dir() or not any(folder.iterdir()):
        frames = list(FrameSource(seq / src.video))
    if variant == "crop":
        assert frames is not None
        h, w = frames[0].shape[:2]
        gt = crop_truth(gt, w - CROP, h - CROP, CROP, CROP)
    if not folder.is_dir() or not any(folder.iterdir()):
        assert frames is not None
        folder.mkdir(parents=True, exist_ok=True)
        for k, f in enumerate(transform(frames, variant), start=1):
            write_image(folder / f"{k:06d}.jpg", f, [cv2.IMWRITE_JPEG_QUALITY, 95])  # any name
    return folder, gt


def synthetic_case(name: str, variant: str) -> tuple[list[Frame], F64] | None:
    """The frames and truth of a synthetic scene's variant (None for ``crop``)."""
    if variant == "crop":
        return None
    scene = make_scene(rng=0) if name == "walkers" else make_busy_scene(name, rng=0)
    return transform(scene.frames, variant), scene.truth


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("detector_robustness", __doc__)
    p.add_argument("--sequences", default="pets,tud," + ",".join(SYNTHETIC))
    p.add_argument("--variants", default="ident,grey,ramp", help="of " + ", ".join(VARIANTS))
    p.add_argument("--detector", default="paper", choices=("paper", "mog2", "knn"))
    p.add_argument("--bootstrap", default="auto", choices=("auto", "spread", "first", "none"))
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--hold-frames", type=int, default=0, help="TrackerConfig.hold_frames (0: off, the default)"
    )
    p.add_argument("--grey-t-min", type=float, default=None, help="PaperConfig.grey_t_min")
    p.add_argument("--grey-shadow-lo", type=float, default=None, help="PaperConfig.grey_shadow_lo")
    p.add_argument("--grey-texture", type=float, default=None, help="PaperConfig.grey_texture")
    p.add_argument(
        "--grey-texture-window", type=int, default=None, help="PaperConfig.grey_texture_window"
    )
    p.add_argument(
        "--grey-texture-erode", type=int, default=None, help="PaperConfig.grey_texture_erode"
    )
    args = p.parse_args(argv)
    from pftrack.detection import PaperConfig
    from pftrack.tracking import TrackerConfig, track_frames

    names = [s for s in args.sequences.split(",") if s]
    variants = [v for v in args.variants.split(",") if v]
    bad = sorted(set(names) - set(REAL) - set(SYNTHETIC)) + sorted(set(variants) - set(VARIANTS))
    if bad:
        p.error(f"unknown sequence(s) or variant(s): {', '.join(bad)}")
    if args.hold_frames < 0:
        p.error(f"--hold-frames is {args.hold_frames}, expected 0 (off) or more")
    if args.hold_frames and args.detector != "paper":
        p.error("--hold-frames needs --detector paper (the hold is the built-in detector's)")
    grey = {
        k: v
        for k, v in (
            ("grey_t_min", args.grey_t_min),
            ("grey_shadow_lo", args.grey_shadow_lo),
            ("grey_texture", args.grey_texture),
            ("grey_texture_window", args.grey_texture_window),
            ("grey_texture_erode", args.grey_texture_erode),
        )
        if v is not None
    }
    if grey and args.detector != "paper":
        p.error("--grey-t-min, --grey-shadow-lo and --grey-texture* need --detector paper")
    try:
        detector: str | PaperConfig = PaperConfig(**grey) if grey else args.detector
    except ValueError as e:
        p.error(str(e))
    data = data_root(args.data)
    header = (
        f"{'sequence':9s} {'variant':7s} {'MOTA':>6s} {'IDF1':>6s} {'HOTA':>6s} "
        f"{'FP':>5s} {'FN':>5s} {'IDSW':>4s} {'s':>6s}"
    )
    with tee_stdout(args.out / "robustness.txt"):
        said = "".join(f" {k}={v:g}" for k, v in grey.items())
        print(
            f"detector={args.detector}{said} bootstrap={args.bootstrap} seed={args.seed} "
            f"hold_frames={args.hold_frames} (MOTA, IDF1, HOTA in %)"
        )
        print(header)
        for name in names:
            for variant in variants:
                case: tuple[object, F64] | None
                if name in REAL:
                    case = real_case(name, variant, data, args.out)
                else:
                    case = synthetic_case(name, variant)
                if case is None:
                    print(f"{name:9s} {variant:7s} skipped (no data, or no such variant)")
                    continue
                source, gt = case
                t0 = time.perf_counter()
                run = track_frames(
                    source,  # type: ignore[arg-type]
                    config=TrackerConfig(detector=detector, hold_frames=args.hold_frames),
                    rng=args.seed,
                    bootstrap=args.bootstrap,
                    show_progress=False,
                )
                s = evaluate_sequence(gt, as_written(run.rows))
                print(
                    f"{name:9s} {variant:7s} {100 * s.mot.mota:6.1f} {100 * s.mot.idf1:6.1f} "
                    f"{100 * s.hota.hota:6.1f} {s.mot.false_positives:5d} {s.mot.misses:5d} "
                    f"{s.mot.num_switches:4d} {time.perf_counter() - t0:6.1f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
