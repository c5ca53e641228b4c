"""A warning that many sequences raise is said once, as an error that many fail with is.

Was: 40 sequences with the same warning printed 40 lines, as they arrived and, for skipped
sequences, before the table; ``BatchSummary.problems()`` listed them all too.
"""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack._text import SaidBefore, opening, said_alike
from pftrack.batch import Job, TaskResult, run_jobs
from pftrack.cli import main
from pftrack.synthetic import make_scene


def _warns(k: int, *said: str) -> TaskResult:
    for text in said:
        warnings.warn(text, stacklevel=1)
    return TaskResult(np.zeros((0, 10)), {}, {"k": k})


def test_said_before_names_the_first_sequence_that_said_it() -> None:
    before = SaidBefore()
    assert before.first("cam01", "frame 3: a box outside the frame") is None
    assert before.first("cam01", "frame 3: a box outside the frame") is None  # its own, again
    assert before.first("cam02", "frame 3: a box outside the frame") == "cam01"
    # the same words but for each one's own name; a name inside a longer one is not its name
    assert before.first("cam02", "/in/cam02.avi: its header says 60 frames") is None
    assert before.first("cam03", "/in/cam03.avi: its header says 60 frames") == "cam02"
    assert before.first("cam1", "/in/cam10.avi: its header says 60 frames") is None
    assert before.first("cam04", "frame 4: a box outside the frame") is None


def test_opening_is_the_first_words() -> None:
    assert opening("no track over 3 frames of the video: too short?", 4) == "no track over 3 ..."
    assert opening("no track", 4) == "no track"
    assert opening("") == ""


def test_the_summary_says_alike_warnings_once_and_keeps_each_entrys_own(
    tmp_path: Path,
) -> None:
    box = "frame 3: 2 detection boxes outside the frame, clipped"
    jobs = [Job(f"cam{k:02d}", _warns, (k, box), ()) for k in range(1, 41)]
    jobs.insert(1, Job("odd", _warns, (0, "its own warning", box), ()))
    jobs += [Job(n, _warns, (0, f"/in/{n}.avi: ended after 30 frames"), ()) for n in ("v", "w")]
    summary = run_jobs(jobs, tmp_path, kind="track", settings={}, n_workers=0)
    assert summary.problems() == [
        f"41 sequences (cam01, odd, cam02..cam40): warning: {box}",
        "odd: warning: its own warning",
        "2 sequences (v, w): warning: /in/NAME.avi: ended after 30 frames",
    ]
    assert summary.table().splitlines()[-3:] == summary.problems()
    on_disk = json.loads((tmp_path / "summary.json").read_text())["sequences"]
    assert [e["warnings"] for e in on_disk] == [e["warnings"] for e in summary.entries]
    assert on_disk[1]["warnings"] == ["its own warning", box]
    assert on_disk[-1]["warnings"] == ["/in/w.avi: ended after 30 frames"]
    # files, for recover and smooth batches
    jobs = [Job(f"t{k}", _warns, (k, "no rows"), ()) for k in range(3)]
    summary = run_jobs(jobs, tmp_path / "o", kind="smooth", settings={}, n_workers=0)
    assert summary.problems() == ["3 files (t0..t2): warning: no rows"]


def test_the_command_says_a_repeated_warning_in_one_short_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """As they arrive: the first in full, the others as ``the same as a's (first words ...)``.
    A skipped sequence's, before the table: alike ones in one line."""
    for name in ("a", "b", "c"):  # three frames of one walker: no track, and the tracker warns
        scene = make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0)
        scene.write_images(tmp_path / "in" / name)
    argv = ["batch", str(tmp_path / "in"), "--out", str(tmp_path / "out"), "--workers", "0"]
    assert main([*argv, "--particles", "30"]) == 0
    err = capsys.readouterr().err.splitlines()
    (said,) = json.loads((tmp_path / "out" / "a.json").read_text())["warnings"]
    assert said.startswith("no track over 3 frames: ")
    assert err == [
        f"a: warning: {said}",
        f"b: warning: the same as a's ({opening(said)})",
        f"c: warning: the same as a's ({opening(said)})",
    ]
    for name in ("b", "c"):  # each file keeps its own
        assert json.loads((tmp_path / "out" / f"{name}.json").read_text())["warnings"] == [said]
    # a re-run skips all three: their earlier warnings, once, before the table
    assert main([*argv, "--particles", "30"]) == 0
    out, err_text = capsys.readouterr()
    assert err_text == f"3 sequences (a, b, c): warning: {said}\n"
    assert out.startswith("name ")


def test_many_sequences_each_with_its_own_warning_are_listed_at_once() -> None:
    """Each pair of messages was matched by a pattern built for it: 1000 sequences, each
    with its own warning, took 37 s to list (0.2 s now; 5 s allowed). Timed in CPU seconds
    of this process: at load 25 the wall clock reached 5.1 s."""
    own = [(f"cam{k:04d}", f"frame {7 * k}: {k % 5} boxes outside the frame") for k in range(1000)]
    named = [(f"v{k:04d}", f"/in/v{k:04d}.avi: ended after {k} frames") for k in range(1000)]
    started = time.process_time()
    assert said_alike(own) == [(m, [n]) for n, m in own]
    assert said_alike(named) == [(m, [n]) for n, m in named]
    before = SaidBefore()
    assert all(before.first(n, m) is None for n, m in own + named)
    assert time.process_time() - started < 5.0
