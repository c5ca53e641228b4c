"""What a camera-network user's trial of ``pftrack batch --scheduler`` found (issue 16).

A real ``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1, a folder of 31 mixed
inputs: what it found and was mended is tested here, on a real cluster where the case needs
one (the watch of the workers is given the scheduler's counts).
"""

from __future__ import annotations

import contextlib
import functools
import json
import logging
import re
import socket
import sys
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.batch import Job, TaskResult, run_jobs, smooth_many
from pftrack.cli import main

distributed = pytest.importorskip("distributed")

#: A cluster's scheduler with its HTTP routes on a free port (8787 may be taken by another run).
NO_DASHBOARD = {"dashboard_address": "127.0.0.1:0"}


def _empty(k: int) -> TaskResult:
    return TaskResult(np.zeros((0, 10)), {}, {"k": k})


class _Kept(logging.Handler):
    """Keeps the messages of the records that reach it."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.said: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.said.append(record.getMessage())


@contextlib.contextmanager
def _said_by(name: str) -> Iterator[list[str]]:
    """The messages the logger `name` passes on to its handlers meanwhile."""
    kept = _Kept()
    logger = logging.getLogger(name)
    logger.addHandler(kept)
    try:
        yield kept.said
    finally:
        logger.removeHandler(kept)


@pytest.fixture(scope="module")
def scheduler() -> Iterator[str]:
    """The address of a running cluster of one worker, as ``dask scheduler`` gives one.

    Without Dask's MALLOC_TRIM_THRESHOLD_: its nanny sets it in this process's environment
    for good (``os.environ.update`` before the spawn), and every later cluster's workers,
    pftrack's too, would inherit it (``test_workers_are_single_threaded`` failed after this).
    """
    import dask

    from pftrack.batch.engine import NO_MALLOC_TRIM

    with dask.config.set({NO_MALLOC_TRIM: None}), distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
        scheduler_kwargs=NO_DASHBOARD,
    ) as cluster:  # fmt: skip
        yield cluster.scheduler_address


def test_a_result_lost_with_its_worker_is_not_said_in_dasks_words(
    scheduler: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The trial: a worker killed (``kill -9``) as it held a finished task's result; the batch
    computed it again and wrote every output, but Dask's client had logged, on stderr among the
    batch's own lines, ``distributed.client - WARNING - Couldn't gather 1 keys, rescheduling
    ('pftrack-track-cam13-bb4d16bf',)``. Here Dask's client says so as the batch takes a
    result, where its gather does; the batch's own lines are unchanged, and the logger's other
    warnings still pass."""
    real = distributed.Future.result

    def result(self: Any, timeout: Any = None) -> Any:
        if sys._getframe(1).f_globals.get("__name__") == "pftrack.batch.engine":
            log = logging.getLogger("distributed.client")
            log.warning("Couldn't gather %s keys, rescheduling %s", 1, (self.key,))
            log.warning("another warning of Dask's client")
        return real(self, timeout=timeout)

    monkeypatch.setattr(distributed.Future, "result", result)
    with _said_by("distributed.client") as said:
        summary = run_jobs(
            [Job(f"f{k}", _empty, (k,), ()) for k in range(2)], tmp_path, kind="smooth",
            settings={}, scheduler=scheduler,
        )  # fmt: skip
    assert [e["status"] for e in summary.entries] == ["done", "done"]
    assert said == ["another warning of Dask's client"] * 2
    with _said_by("distributed.client") as said:  # the batch over: said again
        logging.getLogger("distributed.client").warning("Couldn't gather 1 keys, rescheduling")
    assert said == ["Couldn't gather 1 keys, rescheduling"]


def _free_port() -> int:
    """A port of 127.0.0.1 that nothing listens on (now)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def test_an_unreachable_scheduler_from_the_environment_is_said_to_come_from_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The trial: ``DASK_SCHEDULER_ADDRESS`` left set from an earlier session, ``pftrack batch
    in/ --out out/`` said "cannot connect to the Dask scheduler at tcp://127.0.0.1:8797", an
    address on no command line, nor what to do to run here. Now where it comes from is said,
    and how to run on a local cluster; an address given as ``--scheduler`` stays as it was."""
    import dask

    address = f"tcp://127.0.0.1:{_free_port()}"
    tracks = tmp_path / "in"
    tracks.mkdir()
    for k in range(2):
        (tracks / f"t{k}.txt").write_text("1,1,10,10,5,5,1,-1,-1,-1\n")
    port = address.rsplit(":", 1)[1]  # not Dask's 8786: the command to start it says so
    refused = (
        f"cannot connect to the Dask scheduler at {address}{{}}: connection refused: nothing "
        f"listens on port {port} of 127.0.0.1 (start the scheduler there first: dask scheduler "
        f"--port {port})"
    )
    said = " (from $DASK_SCHEDULER_ADDRESS: unset it to run on a local cluster)"
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", address)  # after Dask read it: read anyway
    assert main(["smooth", str(tracks), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err == f"pftrack smooth: error: {refused.format(said)}\n"
    argv = ["smooth", str(tracks), "--out", str(tmp_path / "out"), "--scheduler", address]
    assert main(argv) == 2
    assert capsys.readouterr().err == f"pftrack smooth: error: {refused.format('')}\n"
    assert not (tmp_path / "out").exists()
    # from Python, the setting in a Dask configuration file (no variable)
    monkeypatch.delenv("DASK_SCHEDULER_ADDRESS")
    with dask.config.set({"scheduler-address": address}), pytest.raises(OSError) as raised:
        smooth_many(tracks, tmp_path / "out")
    said = (
        " (from Dask's scheduler-address setting, in a Dask configuration file: unset it to run "
        "on a local cluster)"
    )
    assert str(raised.value) == refused.format(said)


def test_workers_or_a_scheduler_back_after_the_warning_are_said(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The trial: both workers killed, ``the scheduler ... has lost all its workers; waiting up
    to 30 s for one``, then two new workers, and nothing more was said until the table: the
    batch might as well have been stuck. Now it says when they come back, as when the
    scheduler answers again after it said it had not. Counted here as the scheduler would."""
    from pftrack.batch import engine

    monkeypatch.setattr(engine, "WORKERS_POLL", 0.0)  # the watch counts at every call
    answers: Iterator[int | None] = iter([2, 0, 0, None, 1, 2])

    def n_workers(c: Any, timeout: float | None = None) -> int:
        n = next(answers)
        if n is None:
            raise TimeoutError("no answer")
        return n

    monkeypatch.setattr(engine, "_n_workers", n_workers)
    address = "tcp://127.0.0.1:8799"
    watch = engine._WorkersWatch(None, address, 60.0)  # type: ignore[arg-type]
    said = []
    for _ in range(6):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert not watch.given_up()
        said.append([re.sub(r"after \d+ s", "after N s", str(w.message)) for w in caught])
    assert said == [
        [],
        [
            f"the scheduler at {address} has lost all its workers; waiting up to 60 s for one "
            f"(start one: dask worker {address})"
        ],
        [],
        [
            f"the scheduler at {address} has not answered for 5 s (frozen or overloaded?); "
            "waiting up to 60 s for it"
        ],
        [
            f"the scheduler at {address} answers again after N s; the batch goes on",
            f"the scheduler at {address} has 1 worker again after N s; the batch goes on",
        ],
        [],
    ]


def _interrupted_at(
    monkeypatch: pytest.MonkeyPatch, n: int, before: Callable[[], None] = lambda: None
) -> None:
    """Ctrl-C as the batch (in this process) starts its `n`-th task, after calling `before`."""
    from pftrack.batch import engine

    calls = []
    real = engine.call_task

    def stop_at_the_nth(*args: Any, **kwargs: Any) -> Any:
        calls.append(1)
        if len(calls) == n:
            before()
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(engine, "call_task", stop_at_the_nth)


def _tracks(folder: Path, names: list[str]) -> None:
    folder.mkdir(exist_ok=True)
    for name in names:
        (folder / f"{name}.txt").write_text("1,1,10,10,5,5,1,-1,-1,-1\n3,1,12,10,5,5,1,-1,-1,-1\n")


def test_a_ctrl_c_prints_the_table_of_what_finished(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The trial: after a Ctrl-C, what had finished was only in ``summary.json``. The table a
    batch that ends prints is printed too (done, skipped, failed and cancelled rows), the
    errors on stderr, then the line that says what was left; exit status 130 as before."""
    folder = tmp_path / "in"
    _tracks(folder, ["a"])
    out = tmp_path / "out"
    assert main(["smooth", str(folder), "--out", str(out), "--workers", "0"]) == 0
    _tracks(folder, ["b", "c", "d"])
    (folder / "bad.txt").write_text("not,a,row\n")
    capsys.readouterr()
    _interrupted_at(monkeypatch, 3)  # b done, bad failed, Ctrl-C at c
    assert main(["smooth", str(folder), "--out", str(out), "--workers", "0"]) == 130
    stdout, stderr = capsys.readouterr()
    rows = {line.split()[0]: line.split()[1] for line in stdout.splitlines()[1:6]}
    assert rows == {
        "a": "skipped", "b": "done", "bad": "failed", "c": "cancelled", "d": "cancelled"
    }  # fmt: skip
    assert stdout.splitlines()[6].startswith("5 files: 1 done, 1 skipped, 1 failed, 2 cancelled;")
    assert len(stdout.splitlines()) == 7  # no "summary ->": the last line names it
    *errors, last = stderr.splitlines()
    assert [e.split(": error: ")[0] for e in errors] == ["bad"]
    assert last == (
        "pftrack smooth: interrupted; the outputs of the 1 file finished are written and "
        f"complete; {out / 'summary.json'} lists the rest as cancelled (re-run to finish them)"
    )
    # stopped before the run began: nothing to show
    monkeypatch.setattr("pftrack.batch.engine._make_out_dir", _raise_ctrl_c)
    assert main(["smooth", str(folder), "--out", str(tmp_path / "o2"), "--workers", "0"]) == 130
    assert capsys.readouterr().out == ""


def _raise_ctrl_c(*args: Any) -> None:
    raise KeyboardInterrupt


def test_a_ctrl_c_after_out_was_removed_says_so_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The table of an interrupted batch whose ``--out`` went meanwhile: why ``summary.json``
    is not written is said once, in the last line (not also among the errors)."""
    import shutil

    folder = tmp_path / "in"
    _tracks(folder, ["a", "b"])
    out = tmp_path / "out"
    _interrupted_at(monkeypatch, 2, lambda: shutil.rmtree(out))
    assert main(["smooth", str(folder), "--out", str(out), "--workers", "0"]) == 130
    stdout, stderr = capsys.readouterr()
    assert [line.split()[:2] for line in stdout.splitlines()[1:3]] == [
        ["a", "done"], ["b", "cancelled"]
    ]  # fmt: skip
    assert stderr.count("was removed while the batch ran") == 1
    assert stderr.startswith("pftrack smooth: interrupted; --out ")


def _fails_alike(k: int, error: str, *args: Any) -> TaskResult:
    raise ValueError(error)


def test_sequences_that_fail_alike_are_said_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The trial: 29 sequences left failed ``no worker on the scheduler ... for 8 s``, one line
    each, the same text 29 times. An error is said once, with the count and the names (a
    numbered run as ``first..last``); a task's own error stays its own line; the entries keep
    each error."""
    lost = "no worker on the scheduler at tcp://127.0.0.1:8799 for 8 s"
    jobs = [Job(f"cam{k}", _fails_alike, (k, lost), ()) for k in range(1, 6)]
    jobs.insert(2, Job("odd", _fails_alike, (0, "its own error"), ()))
    jobs.append(Job("pair", _fails_alike, (0, "twice"), ()))
    jobs.append(Job("pair2", _fails_alike, (0, "twice"), ()))
    summary = run_jobs(jobs, tmp_path, kind="track", settings={}, n_workers=0)
    assert summary.problems() == [
        f"5 sequences (cam1..cam5): error: {lost}",
        "odd: error: its own error",
        "2 sequences (pair, pair2): error: twice",
    ]
    errors = [lost, lost, "its own error", lost, lost, lost, "twice", "twice"]
    assert [e["error"] for e in summary.entries] == errors
    on_disk = json.loads((tmp_path / "summary.json").read_text())["sequences"]
    assert [e["error"] for e in on_disk] == [e["error"] for e in summary.entries]
    assert summary.table().splitlines()[-3:] == summary.problems()
    # the command: on stderr, once
    _tracks(tmp_path / "in", [f"t{k}" for k in range(5)])
    monkeypatch.setattr("pftrack.batch.api.smooth_file", functools.partial(_fails_alike, 0, lost))
    argv = ["smooth", str(tmp_path / "in"), "--out", str(tmp_path / "o"), "--workers", "0"]
    assert main(argv) == 1
    assert capsys.readouterr().err == f"5 files (t0..t4): error: {lost}\n"


def test_errors_that_differ_only_by_their_names_are_said_once(tmp_path: Path) -> None:
    """Issue 16's leftover: errors in the same words but each naming its own sequence (``has no
    det/det.txt``, a path) were one line each. Said once, ``NAME`` where each named its own;
    a word of the text that is a name stays; ``seq1`` is not read in ``seq10``; the entries and
    ``summary.json`` keep each sequence's own error."""
    names = [f"cam{k:02d}" for k in range(1, 13)] + ["video", "clip", "seq1", "seq10", "solo"]
    errors = {n: f"--detections auto: sequence {n} has no det/det.txt" for n in names[:12]}
    errors |= {n: f"cannot decode a frame from /in/{n}.mp4: not a video" for n in names[12:14]}
    errors |= {n: f"/in/{n}/seqinfo.ini: /in/{n}/img1 does not exist" for n in names[14:16]}
    errors["solo"] = "/in/solo.avi: its own error, naming solo"
    jobs = [Job(n, _fails_alike, (0, errors[n]), ()) for n in names]
    summary = run_jobs(jobs, tmp_path, kind="track", settings={}, n_workers=0)
    assert summary.problems() == [
        "12 sequences (cam01..cam12): error: --detections auto: sequence NAME has no det/det.txt",
        "2 sequences (video, clip): error: cannot decode a frame from /in/NAME.mp4: not a video",
        "2 sequences (seq1, seq10): error: /in/NAME/seqinfo.ini: /in/NAME/img1 does not exist",
        "solo: error: /in/solo.avi: its own error, naming solo",
    ]
    on_disk = json.loads((tmp_path / "summary.json").read_text())["sequences"]
    assert [e["error"] for e in on_disk] == [errors[n] for n in names]
    # names listed compactly: numbered runs, then four items and "..."
    jobs = [Job(n, _fails_alike, (0, f"{n}: bad"), ()) for n in ("a", "b1", "b2", "c", "d", "e")]
    summary = run_jobs(jobs, tmp_path / "o", kind="smooth", settings={}, n_workers=0)
    assert summary.problems() == ["6 files (a, b1, b2, c, ...): error: NAME: bad"]


def test_a_sequence_certain_to_fail_on_detections_auto_is_not_sent(
    scheduler: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The trial: with ``--detections auto``, each video and image folder without
    ``det/det.txt`` was sent to the cluster as a task, certain to fail on its worker. They are
    refused on the client, before the cluster starts work, as the same failed entry with the
    same message; the others run. None to run: no cluster is asked for."""
    from pftrack.batch import engine, find_sequences, track_many, track_sequence
    from pftrack.batch.tasks import TrackOptions
    from pftrack.io.mot import write_mot
    from pftrack.synthetic import make_scene

    root = tmp_path / "in"
    root.mkdir()
    scene = make_scene(n_frames=8, width=96, height=72, n_walkers=2, rng=0)
    scene.write_video(root / "walk.avi")
    scene.write_images(root / "plain", ext=".png")
    scene.write_images(root / "MOT-01" / "img1", ext=".png")
    (root / "MOT-01" / "det").mkdir()
    det = scene.truth.copy()
    det[:, 1] = -1
    write_mot(root / "MOT-01" / "det" / "det.txt", det)
    options = TrackOptions(detections="auto")
    sent: list[list[str]] = []
    real = engine._run_on_dask

    def spied(c: Any, pending: Any, *args: Any) -> None:
        sent.append([job.name for job in pending])
        real(c, pending, *args)

    monkeypatch.setattr(engine, "_run_on_dask", spied)
    summary = track_many(root, tmp_path / "out", scheduler=scheduler, options=options)
    assert sent == [["MOT-01"]]
    status = {e["name"]: e["status"] for e in summary.entries}
    assert status == {"MOT-01": "done", "plain": "failed", "walk": "failed"}
    for seq in find_sequences(root):
        if seq.name != "MOT-01":  # the message the task raises
            with pytest.raises(ValueError) as raised:
                track_sequence(seq, options)
            (entry,) = [e for e in summary.entries if e["name"] == seq.name]
            assert entry["error"] == str(raised.value)
            assert entry["error"].endswith(f"sequence {seq.name} has no det/det.txt (nor det.txt)")
            assert entry["refused"] is True and "host" not in entry
    # all refused: no cluster connected to nor started, the batch's summary as usual
    monkeypatch.setattr(engine, "dask_client", _no_cluster)
    summary = track_many(
        [root / "walk.avi", root / "plain"], tmp_path / "out2", scheduler=scheduler,
        options=options,
    )  # fmt: skip
    assert [e["status"] for e in summary.entries] == ["failed", "failed"]
    assert "2 sequences: 2 failed; " in summary.table() and "nothing to run" in summary.table()
    assert (tmp_path / "out2" / "summary.json").is_file()


def _no_cluster(*args: Any, **kwargs: Any) -> Any:
    raise AssertionError("a cluster was asked for")
