"""Camera-motion compensation measured on moving-camera versions of PETS09-S2L1 and TUD-Campus.

Each sequence is filmed again through a virtual camera (:func:`pftrack.synthetic.camera_path`):

- ``static``: a fixed crop, zoomed in by 1.35 (the moving version's mean view), resampled the
  same way: the reference the moving version is compared with;
- ``moving``: the same window panned (up to 6 % of the width, 4 % of the height), zoomed
  (1.35 ± 0.1) and rolled (± 3°) smoothly, each a sinusoid (periods 120, 156, 204 and 252
  frames, the same for both sequences).

Frames are written as JPEG image folders with ``gt.txt`` and ``det.txt`` moved by the same
warp (box centre through the affine, size times its zoom, clipped to the image; a box less than
half inside is dropped, in both files alike) under ``--out`` (outside the repository). Then
``pftrack track`` runs on the original, static and moving versions with public detections and
with the built-in detector, with ``--camera-motion off`` and ``auto``, and each result is scored
by :func:`pftrack.eval.evaluate_mot` (MOTA / IDF1). On the original videos ``auto`` must write
the same bytes as ``off`` (a still camera is left alone); the table says so.

The *original* rows are what a user gets: ``pftrack track`` on the data folder's own video,
with the same ``--detections`` / ``--det-scale`` as ``experiments/measure.sh``; seed 0 with
``auto`` is that command with every default, byte for byte. The table gives the mean ± sd
(``np.std``, ddof 0) over seeds 0..N-1, which is not seed 0's figure that measure.sh and the
README quote: the notes under the table give seed 0's MOTA / IDF1 and the seeds' range. The
static and moving versions differ from the original by the 1.35x crop and the JPEG
re-encoding; issue 13 compares the moving version with the static one.

``--set SECTION.FIELD=VALUE`` changes a `TrackerConfig` field of every run on top of the
command's own options, as ``experiments.public_detections --set`` does (e.g.
``lifecycle.relink_coast=5``, which has no command-line option); the runs' files then go to
``tracks-<settings>/`` and the table to ``moving_camera-<settings>.md`` beside the default's,
so one ``--out`` holds both and the versions' frames are made once.

Usage (from the repository root)::

    python -m experiments.moving_camera --out /tmp/moving_camera [--data ../shared/data]
        [--detections public builtin] [--set SECTION.FIELD=VALUE ...]
"""

from __future__ import annotations

import contextlib
import sys
import tempfile
import unittest.mock
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from experiments._common import (
    PETS,
    REPO,
    TUD,
    Source,
    add_detections_and_seeds,
    data_folder,
    experiment_parser,
    tee_stdout,
)
from experiments.public_detections import add_settings, override
from pftrack._typing import F64
from pftrack.cli import main as pftrack_main
from pftrack.cli import track as track_command
from pftrack.eval import evaluate_mot
from pftrack.io.mot import read_mot, write_mot
from pftrack.io.opencv_io import write_image
from pftrack.io.video import read_frames
from pftrack.synthetic import camera_path, warp_frame, warp_rows
from pftrack.tracking import TrackerConfig

PERIOD = 120.0  # frames, both sequences


SEQUENCES = (PETS, TUD)
VERSIONS: dict[str, dict[str, Any]] = {
    "static": {"zoom_swing": 0.0, "pan": (0.0, 0.0), "roll": 0.0},
    "moving": {},
}


def scaled_rows(path: Path, scale: float) -> F64:
    """MOT rows with their boxes multiplied by `scale` (ground truth onto the video's pixels)."""
    rows = read_mot(path, what=path.name)
    rows[:, 2:6] *= scale
    return rows


def make_version(seq: Source, root: Path, out: Path, version: str) -> Path:
    """Write `seq` seen through the `version` camera under `out`; return its folder.

    The folder holds ``img1/000001.jpg ...``, ``gt.txt`` and ``det.txt`` in the new frames'
    pixels. An existing complete folder is reused.
    """
    folder = out / f"{seq.name}-{version}"
    if (folder / "det.txt").is_file():
        return folder
    frames = read_frames(root / seq.name / seq.video)
    size = (frames[0].shape[0], frames[0].shape[1])
    affines = camera_path(len(frames), size, period=PERIOD, **VERSIONS[version])
    images = folder / "img1"
    images.mkdir(parents=True, exist_ok=True)
    for k, (frame, a) in enumerate(zip(frames, affines, strict=True), start=1):
        # any name, atomically (pftrack.io.opencv_io)
        write_image(images / f"{k:06d}.jpg", warp_frame(frame, a), [cv2.IMWRITE_JPEG_QUALITY, 95])
    src = root / seq.name
    write_mot(folder / "gt.txt", warp_rows(scaled_rows(src / "gt.txt", seq.scale), affines, size))
    write_mot(folder / "det.txt", warp_rows(scaled_rows(src / "det.txt", seq.scale), affines, size))
    return folder


def track(
    source: Path, detections: Path | None, det_scale: float, mode: str, seed: int, out: Path
) -> F64:
    """Run ``pftrack track`` and return the rows it wrote."""
    argv = ["track", str(source), "--out", str(out), "--camera-motion", mode, "--seed", str(seed)]
    if detections is not None:
        argv += ["--detections", str(detections), "--det-scale", str(det_scale)]
    if pftrack_main(argv) != 0:
        raise RuntimeError(f"pftrack {' '.join(argv)} failed")
    return read_mot(out, what="tracks")


@contextlib.contextmanager
def settings_applied(settings: Sequence[str]) -> Iterator[None]:
    """``pftrack track`` with every ``--set`` applied (:func:`override`) to its own config."""
    if not settings:
        yield
        return
    own = track_command.tracker_config

    def config(args: Any) -> Any:
        c = own(args)
        for setting in settings:
            c = override(c, setting)
        return c

    with unittest.mock.patch.object(track_command, "tracker_config", config):
        yield


def summary(scores: F64) -> str:
    """``MOTA ± sd / IDF1 ± sd`` of (seeds, 2) scores in %: the table's cell."""
    mean, sd = scores.mean(axis=0), scores.std(axis=0)
    return f"{mean[0]:.1f} ± {sd[0]:.1f} / {mean[1]:.1f} ± {sd[1]:.1f}"


def original_note(name: str, det: str, scores: F64, same: bool) -> str:
    """The note under the table for an original row: `scores` (seeds, 2) are ``auto``'s (the
    default's) MOTA / IDF1 in % for seeds 0, 1, ...; `same` whether ``off`` wrote the same
    bytes for each.

    Seed 0 is the figure ``pftrack track`` gives with every default (measure.sh's and the
    README's), named here beside the seeds' range since the table gives their mean.
    """
    text = f"{name} {det}: auto and off write " + (
        "the same bytes for every seed" if same else "DIFFERENT files"
    )
    lo, hi = scores.min(axis=0), scores.max(axis=0)
    return (
        f"{text}; seed 0 (`pftrack track` with every default, as measure.sh runs it) "
        f"{scores[0, 0]:.1f} / {scores[0, 1]:.1f}; seeds 0-{len(scores) - 1}: "
        f"MOTA {lo[0]:.1f} to {hi[0]:.1f}, IDF1 {lo[1]:.1f} to {hi[1]:.1f}"
    )


def main(argv: Sequence[str] | None = None) -> int:
    ap = experiment_parser("moving_camera", __doc__)
    ap.set_defaults(out=Path(tempfile.gettempdir()) / "pftrack-moving-camera")
    add_detections_and_seeds(ap)
    add_settings(ap, "lifecycle.size_ratio=0.8")
    args = ap.parse_args(argv)
    try:  # a bad setting: exit 2 before any work
        for setting in args.settings:
            override(TrackerConfig(), setting)
    except ValueError as e:
        ap.error(str(e))
    tag = "-".join(s.replace("=", "") for s in args.settings)
    out: Path = args.out.resolve()
    if out == REPO.resolve() or REPO.resolve() in out.parents:
        print(f"--out {out} is inside the repository; give a folder outside it", file=sys.stderr)
        return 2
    root = data_folder(args.data)
    if root is None:
        return 2
    results = out / ("tracks-" + tag if tag else "tracks")
    results.mkdir(parents=True, exist_ok=True)
    lines = [
        f"| sequence | detections | version | off: MOTA / IDF1 (mean ± sd, {args.seeds} seeds) "
        "| auto: MOTA / IDF1 |",
        "| --- | --- | --- | --- | --- |",
    ]
    notes = []
    for seq in SEQUENCES:
        folders = {v: make_version(seq, root, out, v) for v in VERSIONS}
        inputs = {"original": (root / seq.name / seq.video, root / seq.name, seq.scale)}
        inputs |= {v: (f / "img1", f, 1.0) for v, f in folders.items()}
        for det in args.detections:
            for version, (source, folder, scale) in inputs.items():
                same = True
                gt = read_mot(folder / "gt.txt", what="gt")
                by_mode = {}
                for mode in ("off", "auto"):
                    scores = []
                    for seed in range(args.seeds):
                        name = f"{seq.name}-{version}-{det}-{mode}-{seed}.txt"
                        dets = folder / "det.txt" if det == "public" else None
                        with settings_applied(args.settings):
                            rows = track(source, dets, scale, mode, seed, results / name)
                        m = evaluate_mot(gt, rows, scale=scale)
                        scores.append((100 * m.mota, 100 * m.idf1))
                        if mode == "auto":
                            off = results / name.replace("-auto-", "-off-")
                            same &= off.read_bytes() == (results / name).read_bytes()
                    by_mode[mode] = np.asarray(scores)
                if version == "original":
                    notes.append(original_note(seq.name, det, by_mode["auto"], same))
                cells = " | ".join(summary(a) for a in by_mode.values())
                lines.append(f"| {seq.name} | {det} | {version} | {cells} |")
                print(lines[-1], file=sys.stderr, flush=True)
    with tee_stdout(out / (f"moving_camera-{tag}.md" if tag else "moving_camera.md")):
        print("\n".join(lines))
        print()
        print("\n".join(f"- {n}" for n in notes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
