"""The built-in job behind ``pftrack demo``: no data, no download, everything measured."""

from __future__ import annotations

import hashlib
import json
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

#: The demo's outputs, in the order it names them.
OUTPUTS = ("tracks.txt", "truth.txt", "annotated.mp4", "trajectories.png")
#: The hidden file beside them that records what the demo wrote: the SHA-256 of each.
RECORD = ".pftrack-demo.json"


def run_demo(
    out_dir: str | os.PathLike[str], *, seed: int = 0, n_frames: int = 150, particles: int = 100
) -> int:
    """Track a synthetic scene, score it, render it, and show trajectory recovery.

    Writes ``tracks.txt``, ``truth.txt``, ``annotated.mp4`` and ``trajectories.png`` into
    `out_dir`, with the hidden :data:`RECORD` of their SHA-256 (`out_dir` created if missing;
    removed again, when it was created and is still empty, if the run stops before writing
    them; refused, before any work, if it holds a file of these names that is not the one an
    earlier demo wrote, as its record says) and prints MOTA, IDF1 and the rest against the
    scene's known truth. The five files are put in place together: all the new run's, or all
    as they were (a Ctrl-C or SIGTERM while they are renamed is raised after the last:
    :func:`~pftrack.io.atomic.staged_outputs`). An interrupt or error after they are in place
    says they were written (the command's "interrupted; ..." line).
    """
    from dataclasses import replace

    out_dir = check_output_folder(out_dir, "--out-dir")
    wrote = f"{out_dir}/tracks.txt, truth.txt, annotated.mp4, trajectories.png"
    written: list[bool] = []  # set as the last of the files is put in place
    try:
        with made_folder(out_dir, "--out-dir"):
            for name in (*OUTPUTS, RECORD):  # before any work: every output can be written
                check_output(out_dir / name, what="--out-dir", within=out_dir)
            _check_own(out_dir)
            scene = make_scene(n_frames=n_frames, rng=seed)
            base = TrackerConfig()
            config = replace(base, filter=replace(base.filter, n_particles=particles))
            run = track_frames(scene.frames, config=config, rng=seed)
            # the five files are replaced together, or not at all: a Ctrl-C (SIGTERM) during
            # the renames is raised after the last (was: between two, old files beside new)
            with staged_outputs(on_commit=lambda: written.append(True)) as stage:
                staged = {name: stage(out_dir / name) for name in OUTPUTS}
                write_mot(staged["tracks.txt"], run.rows)
                scene.write_truth(staged["truth.txt"])
                write_annotated_video(staged["annotated.mp4"], scene.frames, run.rows, scene.fps)
                plot_trajectories(staged["trajectories.png"], run.rows,
                                  background=scene.background, truth=scene.truth,
                                  title="tracks (colour) over truth (grey)")  # fmt: skip
                record = {name: _sha256(path) for name, path in staged.items()}
                with stage(out_dir / RECORD).open("w", encoding="utf-8") as fh:  # theirs, a
                    json.dump(record, fh, indent=1)  # re-run may replace them (_check_own)
        # the scores and the recovery demo take seconds more: a Ctrl-C there keeps the files
        _report(scene, run, seed=seed, n_frames=n_frames, particles=particles)
    except BaseException as exc:  # was: "interrupted; no output was changed", the files written
        if written:
            from pftrack.cli._signals import set_outcome

            set_outcome(exc, f"the outputs were written before it: {wrote}")
        raise
    print(f"\nwrote {wrote}")
    return 0


def _sha256(path: Path) -> str:
    """The SHA-256 of file `path`, in hex."""
    digest = hashlib.sha256()
    with path.open("rb") as fh:
        while chunk := fh.read(1 << 20):
            digest.update(chunk)
    return digest.hexdigest()


def _check_own(out_dir: Path) -> None:
    """Refuse to replace files of the demo's names in `out_dir` that no earlier demo wrote.

    A file of one of :data:`OUTPUTS`' names is the demo's only when the :data:`RECORD` an
    earlier demo wrote beside it gives its SHA-256. Was: by names alone, some of them were the
    user's (``pftrack demo --out-dir .`` replaced the ``tracks.txt`` of ``pftrack track ...
    --out tracks.txt``, a user trial), all four an earlier demo's, so an earlier demo's file
    the user had replaced by one of their own (their ``tracks.txt``) was written over.
    """
    there = [name for name in OUTPUTS if os.path.lexists(out_dir / name)]
    if not there:
        return
    try:
        record = json.loads((out_dir / RECORD).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        record = None
    if not isinstance(record, dict):
        it = "it" if len(there) == 1 else "them"
        raise ValueError(
            f"--out-dir {out_dir} holds {', '.join(there)}, but no record that pftrack demo "
            f"wrote {it} ({RECORD}): not the demo's to replace; move {it}, or give another "
            "--out-dir"
        )
    for name in there:
        try:
            same = (out_dir / name).is_file() and _sha256(out_dir / name) == record.get(name)
        except OSError:
            same = False
        if not same:
            raise ValueError(
                f"--out-dir {out_dir}: {name} is not the file an earlier pftrack demo wrote "
                f"there ({RECORD} records another): not the demo's to replace; move it, or "
                "give another --out-dir"
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
