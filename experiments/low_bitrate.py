"""The built-in detector on PETS09-S2L1 and TUD-Campus re-encoded as low-bitrate H.264.

Each video is decoded and written again as H.264 (libx264 through PyAV, one key frame every
2 s, the encoder's defaults otherwise) at a bitrate given
in bits per pixel (``--bpp``: bits per second over width x height x frames per second;
0.02 bpp is 24 kbit/s for PETS09's 480x360 at 7 fps, 154 kbit/s for TUD-Campus's 640x480 at
25), and tracked as ``pftrack track FILE`` does (`pftrack.tracking.track_path`: the
built-in detector, every default) for each seed; ``orig`` is the file as it is. The table
gives, per sequence and version, the mean over the seeds of MOTA, IDF1 and HOTA
(`pftrack.eval.evaluate_sequence`, IoU 0.5, the ground truth at the video's scale), the
median :func:`~pftrack.detection.blocking.blockiness` of the first 8 frames (what the
tracker's "heavily compressed" warning decides on) and whether that warning was given.

Usage (from the repository root)::

    python -m experiments.low_bitrate [--data ../shared/data] [--out DIR] [--seeds 0 1 2]
        [--bpp 0.02 0.05 0.1 1.0]
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from fractions import Fraction
from pathlib import Path

import numpy as np

from experiments._common import PETS, TUD, Source, data_root, experiment_parser, tee_stdout
from pftrack._typing import F64
from pftrack.detection.blocking import BLOCK_FRAMES, blockiness
from pftrack.eval import evaluate_sequence
from pftrack.io.mot import read_mot
from pftrack.io.video import FrameSource
from pftrack.tracking.run import track_path

SAID = "the frames are heavily compressed"


def reencode(src: Path, out: Path, bpp: float) -> Path:
    """`src` decoded and written as H.264 at `bpp` bits per pixel (written once, then reused)."""
    if out.exists():
        return out
    import av

    source = FrameSource(src)
    fps = source.fps
    w, h = source.width, source.height
    out.parent.mkdir(parents=True, exist_ok=True)
    part = out.with_suffix(".part.mp4")
    with av.open(str(part), "w") as container:
        stream = container.add_stream("libx264", rate=Fraction(fps).limit_denominator(1000))
        stream.width, stream.height, stream.pix_fmt = w, h, "yuv420p"
        stream.bit_rate = round(bpp * w * h * fps)
        stream.options = {"g": str(round(2 * fps))}
        for frame in source:
            packets = stream.encode(av.VideoFrame.from_ndarray(frame, format="bgr24"))
            container.mux(packets)
        container.mux(stream.encode())
    part.rename(out)
    return out


def first_blockiness(path: Path) -> float:
    """Median blockiness of the first BLOCK_FRAMES frames of `path`."""
    values = []
    for frame in FrameSource(path):
        values.append(blockiness(frame))
        if len(values) == BLOCK_FRAMES:
            break
    return float(np.median(values))


def run(src: Source, path: Path, seeds: Sequence[int], data: Path) -> tuple[F64, bool]:
    """MOTA, IDF1, HOTA (%), FP, FN per seed of `path` (rows), and whether the warning came."""
    gt = read_mot(data / src.name / "gt.txt")
    scores = []
    said = False
    for seed in seeds:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            rows = track_path(path, seed=seed).rows
        said = said or any(SAID in str(w.message) for w in caught)
        s = evaluate_sequence(gt, rows, scale=src.scale)
        m = s.mot
        scores.append([100 * m.mota, 100 * m.idf1, 100 * s.hota.hota, m.false_positives,
                       m.misses])  # fmt: skip
    return np.array(scores), said


def main(argv: Sequence[str] | None = None) -> int:
    """Re-encode, track, score; print the table (also saved to OUT/table.txt)."""
    p = experiment_parser("low_bitrate", __doc__)
    p.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    p.add_argument("--sequences", nargs="+", default=["pets", "tud"], choices=["pets", "tud"])
    p.add_argument("--bpp", type=float, nargs="+", default=[0.02, 0.05, 0.1, 1.0],
                   help="bits per pixel of the re-encoded versions")  # fmt: skip
    args = p.parse_args(argv)
    data = data_root(args.data)
    with tee_stdout(args.out / "table.txt"):
        print(f"seeds {args.seeds}; MOTA / IDF1 / HOTA / FP / FN: mean over the seeds; "
              "MOTA per seed last")  # fmt: skip
        print(f"{'sequence':12} {'version':>10} {'kbit/s':>7} {'block':>6} {'said':>5} "
              f"{'MOTA':>6} {'IDF1':>6} {'HOTA':>6} {'FP':>6} {'FN':>6}  per seed")  # fmt: skip
        for src in [{"pets": PETS, "tud": TUD}[name] for name in args.sequences]:
            orig = data / src.name / src.video
            info = FrameSource(orig)
            pixels = info.width * info.height * info.fps
            versions: list[tuple[str, Path, float]] = [("orig", orig, 0.0)]
            for bpp in args.bpp:
                path = reencode(orig, args.out / f"{src.name}-{bpp:g}bpp.mp4", bpp)
                versions.append((f"{bpp:g} bpp", path, bpp * pixels / 1000))
            for name, path, kbits in versions:
                scores, said = run(src, path, args.seeds, data)
                mota, idf1, hota, fp, fn = scores.mean(axis=0)
                rate = f"{kbits:7.0f}" if kbits else f"{'-':>7}"
                print(
                    f"{src.name:12} {name:>10} {rate} {first_blockiness(path):6.2f} "
                    f"{'yes' if said else 'no':>5} {mota:6.1f} {idf1:6.1f} {hota:6.1f} "
                    f"{fp:6.0f} {fn:6.0f}  {' '.join(f'{v:.1f}' for v in scores[:, 0])}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
