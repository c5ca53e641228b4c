"""``recover``, ``smooth`` and ``batch`` given a folder or several files: --out is a folder."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import pftrack.batch.engine
from pftrack._threads import usable_cpus
from pftrack.batch import recover_many
from pftrack.cli import main
from pftrack.io.mot import write_mot


@pytest.fixture()
def folder(tmp_path: Path) -> Path:
    seq = tmp_path / "seq"
    seq.mkdir()
    rows = np.array([[f, 1, 10.0 + f, 20.0, 30.0, 60.0, 1, -1, -1, -1] for f in (1, 2, 5, 6)])
    write_mot(seq / "a.txt", rows)
    write_mot(seq / "b.txt", rows)
    return seq


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_a_folder_with_a_file_out_is_refused(folder, tmp_path, capsys, command):
    """Was: --workers 0 made a folder named f.txt; without Dask the message was Dask's only."""
    out = tmp_path / "f.txt"
    assert main([command, str(folder), "--out", str(out), "--workers", "0"]) == 2
    err = capsys.readouterr().err
    assert f"{folder} is a folder: pftrack {command} runs the tracks files in it" in err
    assert "--out is a folder" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
    assert main([command, str(folder / "a.txt"), str(folder / "b.txt"), "--out", str(out)]) == 2
    assert "2 inputs: pftrack" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_without_dask_the_message_names_the_folder(folder, tmp_path, capsys, monkeypatch,
                                                   command):  # fmt: skip
    def missing() -> None:
        raise ImportError("No module named 'distributed'", name="distributed")

    monkeypatch.setattr(pftrack.batch.engine, "_require_dask", missing)
    assert main([command, str(folder), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"{folder} is a folder" in err and "--workers 0" in err
    assert not (tmp_path / "out").exists()
    # --workers 0 needs no Dask: the batch runs in this process
    assert main([command, str(folder), "--out", str(tmp_path / "out"), "--workers", "0"]) == 0
    assert sorted(p.name for p in (tmp_path / "out").glob("*.txt")) == ["a.txt", "b.txt"]


def test_batch_with_a_file_out_is_refused(tmp_path, capsys):
    """Was: pftrack batch --out out.txt made a folder named out.txt, as recover's did."""
    from pftrack.synthetic import make_scene

    video = tmp_path / "walk.avi"
    make_scene(n_frames=5, width=64, height=64, n_walkers=1, rng=0).write_video(video)
    out = tmp_path / "out.TXT"
    assert main(["batch", str(video), "--out", str(out), "--workers", "0"]) == 2
    err = capsys.readouterr().err
    assert f"--out is a folder for one output per sequence, not {out}" in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_default_workers_are_the_cores_this_process_may_use(folder, tmp_path, capsys,
                                                                monkeypatch):  # fmt: skip
    """Was: os.cpu_count(), 8 on a machine where taskset or a cpuset gave the process 1."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0}, raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 8)
    assert usable_cpus() == 1
    with pytest.raises(SystemExit):
        main(["batch", "--help"])
    assert "one per core this process may use, 1 here)" in " ".join(capsys.readouterr().out.split())
    sizes: list[int | None] = []

    def no_cluster(client=None, scheduler=None, n_workers=None):
        sizes.append(n_workers)
        raise ValueError("no cluster in this test")

    monkeypatch.setattr(pftrack.batch.engine, "dask_client", no_cluster)
    with pytest.raises(ValueError, match="no cluster in this test"):
        recover_many([folder], tmp_path / "o")  # two files: was a cluster of two workers
    assert sizes == [1]
    monkeypatch.delattr(os, "sched_getaffinity", raising=False)  # not on Linux
    assert usable_cpus() == 8


def test_a_complete_batch_needs_no_scheduler(folder, tmp_path, capsys):
    """Nothing to run: no scheduler is asked, as no local cluster is started (a choice)."""
    argv = ["recover", str(folder), "--out", str(tmp_path / "out")]
    assert main([*argv, "--workers", "0"]) == 0
    capsys.readouterr()
    assert main([*argv, "--scheduler", "tcp://127.0.0.1:1"]) == 0  # nothing listens there
    assert "nothing to run" in capsys.readouterr().out
    assert main([*argv, "--scheduler", "tcp://127.0.0.1:0"]) == 2  # its form is still checked
