"""The first paper's experiment: SIS vs Metropolis-Hastings vs RJ-MCMC in one tracker.

All three samplers run inside :class:`pftrack.tracking.MultiObjectTracker` with the same settings
except ``sampler``, at the same particle budget: ``--particles`` particles per object for SIS and
MH (MH: one chain step per particle, so 2 N likelihoods per object and frame), ``--particles``
kept samples (+ the configured burn-in) of the one joint chain for RJ-MCMC. The chain settings
are ``pftrack track``'s flags, with its defaults and ranges: ``--mh-iter``, ``--mh-proposal``,
``--mh-rw-sigma`` (MH) and ``--burn-in``, ``--moves`` (RJ-MCMC); each sampler reads its own.

Outputs (in ``--out``, default ``out/sampler_experiment``):

* a Markdown table (stdout, and ``sampler_results.md``): Smith's success rate, the
  centroid-distance ratio, MOTA, IDF1, ID switches, tracks and frames/s (whole pipeline: decoding,
  detection, tracking) per sequence and sampler;
* ``sampler_time.png`` and ``sampler_timing.md``: the samplers' time per frame (frame binning and
  foreground mask excluded) against the number of objects in view (synthetic scenes with 1..N
  walkers, ground-truth boxes as the objects / birth candidates) and against the particle budget;
* ``sampler_occlusion.png``: the crossing of walkers 1 and 2 of the synthetic scene, before,
  during and after, one row per sampler (the paper's Figures 1-2).

Usage (from the repository root)::

    python -m experiments.sampler_experiment [--data ../shared/data] [--particles 100] [--seed 0]
        [--max-walkers 8] [--out out/sampler_experiment] [--skip-timing] [--skip-figure]
        [--mh-iter 1] [--mh-proposal dynamics] [--mh-rw-sigma 2 2 0.01] [--burn-in 50]
        [--moves 0.1 0.1 0.7 0.1]
"""

from __future__ import annotations

import itertools
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from experiments._common import data_root, experiment_parser, write_text
from pftrack._limits import MAX_JOINT_SAMPLES
from pftrack.boxes import iou_xywh
from pftrack.cli._options import (
    add_chain_options,
    bounded_int,
    chain_config,
    chain_error,
    non_negative_int,
    positive_int,
)
from pftrack.eval import MotMetrics, evaluate_mot
from pftrack.io.atomic import atomic_path, atomic_write
from pftrack.io.mot import as_written, group_by_frame, read_mot
from pftrack.io.video import FrameSource
from pftrack.particle_filter import (
    ColourParticleFilter,
    MHColourParticleFilter,
    RJMCMCFilter,
    box_histograms,
    hsv_bins,
)
from pftrack.render import draw_tracks
from pftrack.synthetic import Scene, make_scene
from pftrack.tracking import TrackerConfig, load_detections, track_frames
from pftrack.tracking.joint import joint_config

SAMPLERS = ("sis", "mh", "rjmcmc")


@dataclass(frozen=True)
class SamplerResult:
    """One sampler on one sequence."""

    sequence: str
    detector: str
    sampler: str
    metrics: MotMetrics
    n_tracks: int
    fps: float


def config_for(sampler: str, particles: int, base: TrackerConfig | None = None) -> TrackerConfig:
    """The tracker settings of one sampler at a particle budget (everything else shared)."""
    base = base if base is not None else TrackerConfig()
    return replace(base, sampler=sampler, filter=replace(base.filter, n_particles=particles))


def run_sampler(
    source: Any,
    gt: NDArray[np.float64],
    sampler: str,
    *,
    detections: dict[int, NDArray[np.float64]] | None,
    gt_scale: float,
    image_size: tuple[int, int],
    particles: int = 100,
    seed: int = 0,
    sequence: str = "",
    detector: str = "",
    base: TrackerConfig | None = None,
) -> SamplerResult:
    """Track `source` with one sampler and score it against `gt`.

    Parameters
    ----------
    source : path, FrameSource or list of frames
        The video.
    gt : (M, 10) ndarray
        Ground truth (MOT rows); multiplied by `gt_scale` before scoring.
    sampler : {"sis", "mh", "rjmcmc"}
    detections : dict or None
        Per-frame detections in video pixels (None: the built-in detector).
    gt_scale : float
        Ground truth to video pixels.
    image_size : (width, height)
        For the centroid-distance ratio.
    particles : int
        Particle budget.
    seed : int
        Tracker seed.
    sequence, detector : str
        The row's labels.
    base : TrackerConfig, optional
        The settings every sampler shares, its chain settings among them (default
        ``TrackerConfig()``; :func:`config_for`).
    """
    # online output (no offline linking or smoothing): the samplers are what is compared
    run = track_frames(
        source,
        detections=detections,
        config=config_for(sampler, particles, base),
        rng=seed,
        show_progress=False,
        smoother=None,
        link=None,
    )
    m = evaluate_mot(gt, as_written(run.rows), scale=gt_scale, image_size=image_size)
    n_tracks = len(np.unique(run.rows[:, 1])) if len(run.rows) else 0
    return SamplerResult(sequence, detector, sampler, m, n_tracks, run.fps)


def format_table(results: Sequence[SamplerResult]) -> str:
    """Markdown table of the results."""
    lines = [
        "| sequence | detections | sampler | success | strict success | centroid ratio (1e-5) "
        "| MOTA | IDF1 | ID sw. | tracks | frames/s |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        m = r.metrics
        lines.append(
            f"| {r.sequence} | {r.detector} | {r.sampler} | {m.success_rate:.3f} | "
            f"{m.success_rate_strict:.3f} | {m.centroid_distance_ratio * 1e5:.2f} | "
            f"{m.mota * 100:.1f} | {m.idf1 * 100:.1f} | {m.num_switches} | {r.n_tracks} | "
            f"{r.fps:.0f} |"
        )
    return "\n".join(lines)


def _frames_of(path: Path, max_frames: int | None) -> Any:
    if max_frames is None:
        return str(path)
    return list(itertools.islice(iter(FrameSource(path)), max_frames))


def real_sequences(data: Path, max_frames: int | None = None) -> list[dict[str, Any]]:
    """The PETS09-S2L1 and TUD-Campus runs (sequences whose folder exists)."""
    out: list[dict[str, Any]] = []
    pets, tud = data / "pets09-s2l1", data / "tud-campus"
    if pets.is_dir():
        gt = read_mot(pets / "gt.txt")
        frames = _frames_of(pets / "video.avi", max_frames)
        out.append(
            dict(
                sequence="PETS09-S2L1",
                detector="public",
                source=frames,
                gt=gt,
                gt_scale=0.625,
                image_size=(480, 360),
                detections=load_detections(pets / "det.txt", 0.625),
            )
        )
        out.append(
            dict(
                sequence="PETS09-S2L1",
                detector="built-in",
                source=frames,
                gt=gt,
                gt_scale=0.625,
                image_size=(480, 360),
                detections=None,
            )
        )
    if tud.is_dir():
        out.append(
            dict(
                sequence="TUD-Campus",
                detector="public",
                source=_frames_of(tud / "video.mp4", max_frames),
                gt=read_mot(tud / "gt.txt"),
                gt_scale=1.0,
                image_size=(640, 480),
                detections=load_detections(tud / "det.txt", 1.0),
            )
        )
    if max_frames is not None:
        for s in out:
            s["gt"] = s["gt"][s["gt"][:, 0] <= max_frames]
            if s["detections"] is not None:
                s["detections"] = {f: d for f, d in s["detections"].items() if f <= max_frames}
    return out


def synthetic_run(scene: Scene, name: str = "synthetic") -> dict[str, Any]:
    """A synthetic scene run with the built-in detector."""
    return dict(
        sequence=name,
        detector="built-in",
        source=scene.frames,
        gt=scene.truth,
        gt_scale=1.0,
        image_size=(scene.width, scene.height),
        detections=None,
    )


def truth_detections(scene: Scene) -> dict[int, NDArray[np.float64]]:
    """Ground-truth boxes as detections (score 1) per frame."""
    return {
        f: np.column_stack([r[:, 2:6], np.ones(len(r))])
        for f, r in group_by_frame(scene.truth).items()
    }


def time_per_frame(
    scene: Scene, sampler: str, particles: int, seed: int = 0, base: TrackerConfig | None = None
) -> float:
    """Mean seconds per frame spent in the sampler alone, one scene.

    The frame-level work every sampler shares (colour binning, the foreground mask: here the
    difference to the scene's empty background) is done before the clock starts; objects are the
    ground-truth boxes: SIS and MH step one filter per object in view, RJ-MCMC one joint chain
    with the boxes as birth candidates. Same budget and dynamics as in the tracker.
    """
    cfg = config_for(sampler, particles, base)
    rng = np.random.default_rng(seed)
    frames = group_by_frame(scene.truth)
    filters: dict[int, Any] = {}
    joint = None
    if sampler == "rjmcmc":
        joint = RJMCMCFilter(joint_config(cfg), rng=rng)
    # the MH chain as the tracker runs it (pftrack.tracking.track): was n_iter 1 whatever
    # the configuration said
    mh = {"n_iter": cfg.mh_iter, "proposal": cfg.mh_proposal, "rw_sigma": cfg.mh_rw_sigma}
    total = 0.0
    for n, frame in enumerate(scene.frames, start=1):
        diff = cv2.absdiff(frame, scene.background).max(axis=2)
        mask = (diff > 30).astype(np.uint8)
        binned = hsv_bins(frame, mask, cfg.binning)
        rows = frames.get(n, np.zeros((0, 10)))
        boxes = (
            np.column_stack([rows[:, 2:4] + rows[:, 4:6] / 2, rows[:, 4:6]])
            if len(rows)
            else np.zeros((0, 4))
        )
        refs = box_histograms(binned, boxes, "uniform") if len(rows) else None
        for k, r in enumerate(rows):
            if (
                joint is None
                and int(r[1]) not in filters
                and refs is not None
                and refs[k].sum() > 0
            ):
                filters[int(r[1])] = (
                    MHColourParticleFilter(boxes[k], refs[k], cfg.filter, rng=rng, **mh)
                    if sampler == "mh"
                    else ColourParticleFilter(boxes[k], refs[k], cfg.filter, rng=rng)
                )
        in_view = {int(r[1]) for r in rows}
        start = time.perf_counter()
        if joint is not None:
            joint.step(binned, mask, boxes)
        else:
            for i, f in filters.items():
                if i in in_view:
                    f.step(binned)
        total += time.perf_counter() - start
    return total / len(scene.frames)


def timing_vs_objects(
    max_walkers: int,
    particles: int,
    n_frames: int = 40,
    seed: int = 0,
    base: TrackerConfig | None = None,
) -> dict[str, list[tuple[float, float]]]:
    """(mean objects in view, ms/frame) per sampler for scenes with 1..max_walkers walkers.

    The walkers all start inside the view (scene frames from the middle of a longer scene are
    used), so that the count in view grows with the number of walkers.
    """
    out: dict[str, list[tuple[float, float]]] = {s: [] for s in SAMPLERS}
    for k in range(1, max_walkers + 1):
        scene = make_scene(n_frames=3 * n_frames, n_walkers=k, rng=seed, occluder=False)
        sub = _middle(scene, n_frames)
        n_obj = len(sub.truth) / n_frames
        for s in SAMPLERS:
            out[s].append((n_obj, 1e3 * time_per_frame(sub, s, particles, seed, base)))
    return out


def _middle(scene: Scene, n_frames: int) -> Scene:
    """The `n_frames` frames of `scene` with the most objects in view (frames renumbered from 1)."""
    counts = np.bincount(scene.truth[:, 0].astype(int), minlength=len(scene.frames) + 1)[1:]
    window = np.convolve(counts, np.ones(n_frames), mode="valid")
    first = int(np.argmax(window))
    keep = (scene.truth[:, 0] > first) & (scene.truth[:, 0] <= first + n_frames)
    truth = scene.truth[keep].copy()
    truth[:, 0] -= first
    return replace(scene, frames=scene.frames[first : first + n_frames], truth=truth)


def timing_vs_particles(
    budgets: Sequence[int],
    n_walkers: int = 4,
    n_frames: int = 40,
    seed: int = 0,
    base: TrackerConfig | None = None,
) -> dict[str, list[tuple[float, float]]]:
    """(particles, ms/frame) per sampler on one synthetic scene."""
    sub = _middle(
        make_scene(n_frames=3 * n_frames, n_walkers=n_walkers, rng=seed, occluder=False), n_frames
    )
    return {
        s: [(float(n), 1e3 * time_per_frame(sub, s, n, seed, base)) for n in budgets]
        for s in SAMPLERS
    }


_STYLE = {
    "sis": ("tab:blue", "o", "SIS (paper)"),
    "mh": ("tab:orange", "s", "MH per object"),
    "rjmcmc": ("tab:green", "^", "RJ-MCMC joint"),
}


def plot_timing(
    by_objects: dict[str, list[tuple[float, float]]],
    by_particles: dict[str, list[tuple[float, float]]],
    path: Path,
    particles: int,
    n_walkers: int,
) -> Path:
    """Two panels: ms/frame against objects in view and against the particle budget."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4), dpi=90)
    for s in SAMPLERS:
        c, mk, label = _STYLE[s]
        x, y = np.array(by_objects[s]).T
        axes[0].plot(x, y, marker=mk, color=c, label=label)
        x, y = np.array(by_particles[s]).T
        axes[1].plot(x, y, marker=mk, color=c, label=label)
    axes[0].set(
        xlabel="objects in view (mean per frame)",
        ylabel="sampler ms / frame",
        title=f"{particles} particles / samples",
    )
    axes[1].set(
        xlabel="particles per object (SIS, MH) / kept samples (RJ-MCMC)",
        ylabel="sampler ms / frame",
        title=f"synthetic scene, {n_walkers} walkers",
        xscale="log",
        yscale="log",
    )
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
    return path


def crossing_frame(scene: Scene, a: int = 1, b: int = 2) -> int:
    """The frame where walkers `a` and `b` overlap most (their crossing)."""
    best, frame = -1.0, 1
    for f, rows in group_by_frame(scene.truth).items():
        ra, rb = rows[rows[:, 1] == a], rows[rows[:, 1] == b]
        if len(ra) and len(rb):
            v = float(iou_xywh(ra[:, 2:6], rb[:, 2:6])[0, 0])
            if v > best:
                best, frame = v, f
    return frame


def occlusion_figure(
    scene: Scene,
    path: Path,
    particles: int = 100,
    seed: int = 0,
    offset: int = 8,
    crop: tuple[int, int] = (200, 130),
    base: TrackerConfig | None = None,
) -> Path:
    """Frames before, during and after walkers 1 and 2 cross, one row per sampler (PNG)."""
    fc = crossing_frame(scene)
    frames = [max(1, fc - offset), fc, min(len(scene.frames), fc + offset)]
    rows_by = {}
    for s in SAMPLERS:
        run = track_frames(
            scene.frames,
            config=config_for(s, particles, base),
            rng=seed,
            show_progress=False,
            smoother=None,
            link=None,
        )
        rows_by[s] = run.rows
    g = scene.truth[(scene.truth[:, 0] == fc) & np.isin(scene.truth[:, 1], (1, 2))]
    cx = float(np.mean(g[:, 2] + g[:, 4] / 2))
    cy = float(np.mean(g[:, 3] + g[:, 5] / 2))
    cw, ch = crop
    x0 = int(np.clip(cx - cw / 2, 0, scene.width - cw))
    y0 = int(np.clip(cy - ch / 2, 0, scene.height - ch))
    grid = []
    for s in SAMPLERS:
        tiles = []
        for f in frames:
            r = rows_by[s]
            crop_img = draw_tracks(scene.frames[f - 1], r[r[:, 0] == f])[y0 : y0 + ch, x0 : x0 + cw]
            img = cv2.copyMakeBorder(
                crop_img, 16, 2, 2, 2, cv2.BORDER_CONSTANT, value=(255, 255, 255)
            )
            label = f"{_STYLE[s][2]}, frame {f}"
            cv2.putText(
                img, label, (4, 12), cv2.FONT_HERSHEY_SIMPLEX, 0.38, (0, 0, 0), 1, cv2.LINE_AA
            )
            tiles.append(img)
        grid.append(np.hstack(tiles))
    out = np.vstack(grid)
    path.parent.mkdir(parents=True, exist_ok=True)
    from PIL import Image  # a matplotlib dependency; 128-colour palette keeps the PNG small

    png = Image.fromarray(cv2.cvtColor(out, cv2.COLOR_BGR2RGB)).quantize(colors=128)
    with atomic_write(path, "wb") as fh:
        png.save(fh, format="PNG", optimize=True)
    return path


def main(argv: Sequence[str] | None = None) -> int:
    p = experiment_parser("sampler_experiment", __doc__)
    # every value checked here, before any work (was: --particles 0 a traceback, --max-walkers
    # 41 one after the whole table had run)
    p.add_argument(
        "--particles", type=bounded_int(1, MAX_JOINT_SAMPLES), default=100,
        help=f"particles per object (SIS, MH) and kept samples of the joint chain, 1 to "
        f"{MAX_JOINT_SAMPLES} (the limit of pftrack track and pftrack.Tracker for the chain)",
    )  # fmt: skip
    p.add_argument("--seed", type=non_negative_int, default=0, help="random seed, >= 0")
    p.add_argument(
        "--max-walkers", type=bounded_int(1, 40), default=8,
        help="timing: synthetic scenes of 1 to this many walkers, 1 to 40",
    )  # fmt: skip
    p.add_argument(
        "--max-frames", type=positive_int, default=None,
        help="only the first frames of each real sequence, >= 1 (default: all)",
    )  # fmt: skip
    p.add_argument("--skip-timing", action="store_true")
    p.add_argument("--skip-figure", action="store_true")
    add_chain_options(p)  # pftrack track's, with its defaults and ranges
    args = p.parse_args(argv)
    refused = chain_error(args)
    if refused:
        p.error(refused)
    base = chain_config(args, TrackerConfig())
    if not (args.skip_timing and args.skip_figure):  # the two figures: before any work
        import importlib.util

        missing = [m for m in ("matplotlib", "PIL") if importlib.util.find_spec(m) is None]
        if missing:  # was: the whole table run, then ModuleNotFoundError: No module named 'PIL'
            p.error(
                f"the figures need {' and '.join(missing)}, which pftrack does not install: "
                "pip install matplotlib, or pass --skip-timing --skip-figure"
            )

    data = data_root(args.data)
    runs = real_sequences(data, args.max_frames)
    if not runs:
        print(f"note: no sequence under {data}; synthetic scene only", file=sys.stderr)
    runs.append(synthetic_run(make_scene(n_frames=150, n_walkers=6, rng=args.seed)))
    results = []
    for r in runs:
        for s in SAMPLERS:
            res = run_sampler(
                r["source"],
                r["gt"],
                s,
                detections=r["detections"],
                gt_scale=r["gt_scale"],
                image_size=r["image_size"],
                particles=args.particles,
                seed=args.seed,
                sequence=r["sequence"],
                detector=r["detector"],
                base=base,
            )
            results.append(res)
            print(
                f"{r['sequence']} {r['detector']} {s}: MOTA {res.metrics.mota * 100:.1f} "
                f"IDF1 {res.metrics.idf1 * 100:.1f}",
                file=sys.stderr,
            )
    table = format_table(results)
    chain = (
        f"--mh-iter {args.mh_iter} --mh-proposal {args.mh_proposal} --mh-rw-sigma "
        f"{' '.join(f'{v:g}' for v in args.mh_rw_sigma)} --burn-in {args.burn_in} --moves "
        f"{' '.join(f'{v:g}' for v in args.moves)}"
    )
    header = (
        f"<!-- python -m experiments.sampler_experiment --particles {args.particles} "
        f"--seed {args.seed} --max-walkers {args.max_walkers} {chain} -->\n"
    )
    print(table)
    write_text(args.out / "sampler_results.md", header + table + "\n")
    if not args.skip_timing:
        by_obj = timing_vs_objects(args.max_walkers, args.particles, seed=args.seed, base=base)
        budgets = (25, 50, 100, 200, 400, 800)
        by_n = timing_vs_particles(budgets, seed=args.seed, base=base)
        plot_timing(by_obj, by_n, args.out / "sampler_time.png", args.particles, 4)
        lines = [
            "| sampler | " + " | ".join(f"{x:.1f} obj" for x, _ in by_obj["sis"]) + " |",
            "|---|" + "---|" * len(by_obj["sis"]),
        ]
        for s in SAMPLERS:
            lines.append(f"| {s} | " + " | ".join(f"{y:.2f}" for _, y in by_obj[s]) + " |")
        lines += [
            "",
            "| sampler | " + " | ".join(f"N={n}" for n in budgets) + " |",
            "|---|" + "---|" * len(budgets),
        ]
        for s in SAMPLERS:
            lines.append(f"| {s} | " + " | ".join(f"{y:.2f}" for _, y in by_n[s]) + " |")
        timing = "\n".join(lines)
        print("\nms per frame\n" + timing)
        write_text(args.out / "sampler_timing.md", header + timing + "\n")
    if not args.skip_figure:
        occlusion_figure(
            make_scene(n_frames=150, n_walkers=6, rng=args.seed),
            args.out / "sampler_occlusion.png",
            args.particles,
            args.seed,
            base=base,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
