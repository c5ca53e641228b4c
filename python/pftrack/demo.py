"""The built-in job behind ``pftrack demo``: no data, no download, everything measured."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from pftrack._text import counted
from pftrack.eval import evaluate_mot, format_metrics
from pftrack.io.atomic import check_output, check_output_folder, made_folder, staged_outputs
from pftrack.io.mot import as_written, write_mot
from pftrack.recovery.demo import demo_report
from pftrack.render import plot_trajectories, write_annotated_video
from pftrack.synthetic import Scene, make_scene
from pftrack.tracking import TrackerConfig, TrackingRun, track_frames

__all__ = ["run_demo"]


def run_demo(
    out_dir: str | os.PathLike[str], *, seed: int = 0, n_frames: int = 150, particles: int = 100
) -> int:
    """Track a synthetic scene, score it, render it, and show trajectory recovery.

    Writes ``tracks.txt``, ``truth.txt``, ``annotated.mp4`` and ``trajectories.png`` into
    `out_dir` (created if missing; removed again, when it was created and is still empty, if
    the run stops before writing them; refused, before any work, if it holds some of these
    files but not all four, an earlier demo's) and prints MOTA, IDF1 and the rest against the
    scene's known truth. An interrupt or error after the files are written says they were (the
    command's "interrupted; ..." line).
    """
    from dataclasses import replace

    out_dir = check_output_folder(out_dir, "--out-dir")
    names = ("tracks.txt", "truth.txt", "annotated.mp4", "trajectories.png")
    with made_folder(out_dir, "--out-dir"):
        for name in names:  # before any work: every output can be written
            check_output(out_dir / name, what="--out-dir", within=out_dir)
        _check_own(out_dir, names)
        scene = make_scene(n_frames=n_frames, rng=seed)
        base = TrackerConfig()
        config = replace(base, filter=replace(base.filter, n_particles=particles))
        run = track_frames(scene.frames, config=config, rng=seed)
        with staged_outputs() as stage:  # the four files are replaced together, or not at all
            write_mot(stage(out_dir / "tracks.txt"), run.rows)
            scene.write_truth(stage(out_dir / "truth.txt"))
            write_annotated_video(
                stage(out_dir / "annotated.mp4"), scene.frames, run.rows, scene.fps
            )
            plot_trajectories(stage(out_dir / "trajectories.png"), run.rows,
                              background=scene.background, truth=scene.truth,
                              title="tracks (colour) over truth (grey)")  # fmt: skip
    wrote = f"{out_dir}/tracks.txt, truth.txt, annotated.mp4, trajectories.png"
    try:  # the scores and the recovery demo take seconds more: a Ctrl-C there keeps the files
        _report(scene, run, seed=seed, n_frames=n_frames, particles=particles)
    except BaseException as exc:  # was: "interrupted; no output was changed", the files written
        from pftrack.cli._signals import set_outcome

        set_outcome(exc, f"the outputs were written before it: {wrote}")
        raise
    print(f"\nwrote {wrote}")
    return 0


def _check_own(out_dir: Path, names: tuple[str, ...]) -> None:
    """Refuse to replace files of the demo's names in `out_dir` that no earlier demo wrote.

    An earlier demo leaves all four (they are renamed into place together); some of them alone
    are the user's: ``pftrack demo --out-dir .`` replaced the ``tracks.txt`` that ``pftrack
    track ... --out tracks.txt`` had written there (a user trial; ``pftrack batch`` likewise
    replaces only its own files).
    """
    there = [name for name in names if os.path.lexists(out_dir / name)]
    if there and len(there) < len(names):
        raise ValueError(
            f"--out-dir {out_dir} holds {', '.join(there)}, but not all four files of an "
            f"earlier pftrack demo ({', '.join(names)}): not the demo's to replace; move them, "
            "or give another --out-dir"
        )


def _report(scene: Scene, run: TrackingRun, *, seed: int, n_frames: int, particles: int) -> None:
    """Print the scores of the files written, then the recovery demo's table."""
    # tracks.txt's values (rounded to 2 decimals): the scores pftrack eval gives the files
    # (was: the unrounded rows', seed 2 MOTA 16.1 against the file's 15.7)
    size = (scene.width, scene.height)
    metrics = evaluate_mot(scene.truth, as_written(run.rows), image_size=size)
    walkers = len(np.unique(scene.truth[:, 1]))
    print(f"pftrack demo: synthetic scene, {counted(n_frames, 'frame')} "
          f"{scene.width}x{scene.height}, {counted(walkers, 'walker')}, seed {seed}")  # fmt: skip
    print(f"tracked at {run.fps:.0f} frames/s (detection + {particles} particles per object)")
    print(format_metrics({"pftrack": metrics}))
    print()
    print(demo_report(scene.truth, rng=seed))
