"""What a camera-network user's trial of ``pftrack batch --scheduler`` found (issue 16).

A real ``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1, a folder of 31 mixed
inputs: what it found and was mended is tested here, on a real cluster where the case needs
one (the watch of the workers is given the scheduler's counts).
"""

from __future__ import annotations

import contextlib
import logging
import re
import socket
import sys
import warnings
from collections.abc import Iterator
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
    """The address of a running cluster of one worker, as ``dask scheduler`` gives one."""
    with distributed.LocalCluster(
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
    refused = (
        f"cannot connect to the Dask scheduler at {address}{{}}: connection refused: nothing "
        f"listens on port {address.rsplit(':', 1)[1]} of 127.0.0.1 (start the scheduler there "
        "first: dask scheduler)"
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
