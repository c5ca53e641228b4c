"""After a Ctrl-C that code in C dropped, no command puts an output in place.

The ``pftrack`` console script's SIGINT handler notes each Ctrl-C (:mod:`pftrack._interrupt`)
before it raises; code in C may drop the ``KeyboardInterrupt`` (an interrupted import of
NumPy's once let ``pftrack recover`` write its output, exit status 0). Only ``recover`` and
``smooth`` checked the flag, before their one write. Now the atomic writers check it where
they put an output in place, so every command that writes ends as interrupted instead: exit
status 130, ``pftrack CMD: interrupted; no output was changed``, every file as it was and no
temporary file. Here the flag is set as the handler sets it, and the interrupt is not raised
(dropped); tests/test_cli_lost_interrupt.py sends a real SIGINT to a subprocess.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from pftrack import _interrupt
from pftrack.cli import main
from pftrack.io.mot import write_mot
from pftrack.synthetic import make_scene
from tests.earlier_outputs import earlier as earlier_bytes
from tests.earlier_outputs import write_earlier

EARLIER = b"an earlier run's output\n"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("inputs")
    scene = make_scene(n_frames=20, rng=0)
    write_mot(d / "tracks.txt", scene.truth[scene.truth[:, 0] != 9])  # a gap in every track
    gt, video = scene.write_truth(d / "gt.txt"), scene.write_video(d / "v.avi")
    return {"video": video, "gt": gt, "tracks": d / "tracks.txt"}


@pytest.fixture(autouse=True)
def _flag_cleared() -> Iterator[None]:
    """The flag is the process's: no test leaves it set for the next."""
    _interrupt.clear()
    yield
    _interrupt.clear()


def _write_earlier(path: Path) -> None:
    """An earlier run's output at `path`, of its kind as pftrack writes it (pftrack replaces
    no file of another's: tests/earlier_outputs.py)."""
    write_earlier(path)


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    return {p.name: (p.read_bytes() if p.is_file() else None) for p in folder.iterdir()}


# each command and the outputs it writes in `out` (a folder), which hold an earlier run's
COMMANDS: dict[str, tuple[list[str], Any]] = {
    "track": (
        ["t.txt", "v.mp4", "p.png"],
        lambda i, o: ["track", str(i["video"]), "--out", str(o / "t.txt"), "--render",
                      str(o / "v.mp4"), "--plot", str(o / "p.png"), "--particles", "20"],
    ),
    "render": (
        ["v.mp4", "p.png"],
        lambda i, o: ["render", str(i["video"]), str(i["gt"]), "--out", str(o / "v.mp4"),
                      "--plot", str(o / "p.png")],
    ),
    "smooth": (["s.txt"], lambda i, o: ["smooth", str(i["tracks"]), "--out", str(o / "s.txt")]),
    "recover": (
        ["r.txt"],
        lambda i, o: ["recover", str(i["tracks"]), "--out", str(o / "r.txt"), "--method",
                      "linear"],
    ),
    "eval": (
        ["e.json", "e.csv"],
        lambda i, o: ["eval", "--gt", str(i["gt"]), "--res", str(i["tracks"]), "--json",
                      str(o / "e.json"), "--csv", str(o / "e.csv")],
    ),
    "experiment": (
        ["x.json", "x.png"],
        lambda i, o: ["experiment", "gaps", "--gt", str(i["gt"]), "--mask", "0,0,40,40",
                      "--methods", "linear", "--repeat", "1", "--json", str(o / "x.json"),
                      "--figure", str(o / "x.png")],
    ),
}  # fmt: skip


def _said(command: str) -> str:
    """The line an interrupted `command` ends with (``experiment gaps`` names its experiment)."""
    prog = "pftrack experiment gaps" if command == "experiment" else f"pftrack {command}"
    return f"{prog}: interrupted; no output was changed\n"


@pytest.mark.filterwarnings("ignore::UserWarning")  # a 20-frame scene's notes, not the subject
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_lost_ctrl_c_changes_no_output(
    command: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Into a folder that holds an earlier run's outputs, then into an empty one."""
    names, argv = COMMANDS[command]
    out, fresh = tmp_path / "out", tmp_path / "fresh"
    out.mkdir()
    fresh.mkdir()
    assert main(["-q", *argv(inputs, out)]) == 0, capsys.readouterr().err  # the command works
    assert sorted(p.name for p in out.iterdir()) == sorted(names)
    for name in names:
        _write_earlier(out / name)
    earlier = _snapshot(out)
    capsys.readouterr()
    for folder in (out, fresh):
        _interrupt.remember()  # as the handler does; its KeyboardInterrupt dropped by code in C
        assert main(["-q", *argv(inputs, folder)]) == 130
        assert capsys.readouterr().err == _said(command)
    assert _snapshot(out) == earlier  # and no temporary file
    assert list(fresh.iterdir()) == []


@pytest.mark.filterwarnings("ignore:no track over 5 frames")  # 5 frames: no track confirmed
def test_a_lost_ctrl_c_makes_no_demo(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``demo`` removes the folder it made, as after a Ctrl-C it received."""
    _interrupt.remember()
    assert main(["-q", "demo", "--out-dir", str(tmp_path / "d"), "--frames", "5"]) == 130
    assert capsys.readouterr().err == "pftrack demo: interrupted; no output was changed\n"
    assert list(tmp_path.iterdir()) == []


@pytest.fixture(scope="module")
def two_videos(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("videos")
    for k, name in enumerate(("a", "b")):
        make_scene(n_frames=10, rng=k).write_video(d / f"{name}.avi")
    return d


def _batch(videos: Path, out: Path) -> int:
    return main(["-q", "batch", str(videos), "--out", str(out), "--workers", "0",
                 "--particles", "20"])  # fmt: skip


def _statuses(out: Path) -> dict[str, str]:
    summary = json.loads((out / "summary.json").read_text())
    return {e["name"]: e["status"] for e in summary["sequences"]}


@pytest.mark.filterwarnings("ignore::UserWarning")  # 10-frame scenes: few tracks confirmed
@pytest.mark.parametrize("after", [0, 1, 2])
def test_a_lost_ctrl_c_stops_a_batch_and_a_re_run_finishes_it(
    after: int,
    two_videos: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Ctrl-C lost while a sequence is tracked (after `after` sequences are written): that
    sequence's outputs are not written (its old ones, if any, stay), the batch ends as one
    Ctrl-C'd there does (exit 130; summary.json lists the finished and the cancelled), and a
    re-run skips the finished and makes the rest, as a batch never interrupted does. Lost
    after the last one (``after`` 2): every output is written, and the batch still ends as
    interrupted. Was: the batch went on and wrote every output, exit status 0."""
    import pftrack.batch.engine as engine

    whole = tmp_path / "whole"
    assert _batch(two_videos, whole) == 0
    real_write = engine._write
    calls = [0]

    def write(*args: Any, **kwargs: Any) -> Any:
        if calls[0] == after:
            _interrupt.remember()  # while this sequence was tracked, dropped
        calls[0] += 1
        entry = real_write(*args, **kwargs)
        if calls[0] == after == 2:
            _interrupt.remember()  # after the last sequence's outputs
        return entry

    monkeypatch.setattr(engine, "_write", write)
    out = tmp_path / "out"
    capsys.readouterr()
    assert _batch(two_videos, out) == 130
    err = capsys.readouterr().err.strip().splitlines()[-1]
    if after == 0:
        assert err == (
            f"pftrack batch: interrupted; no sequence was finished; {out}/summary.json lists "
            "them as cancelled (re-run to run them)"
        )
    else:
        finished = "1 sequence" if after == 1 else "2 sequences"
        assert err == (
            f"pftrack batch: interrupted; the outputs of the {finished} finished are written and "
            f"complete; {out}/summary.json lists the rest as cancelled (re-run to finish them)"
        )
    done = ["a", "b"][:after]
    assert _statuses(out) == {n: "done" if n in done else "cancelled" for n in ("a", "b")}
    expected = ["summary.json", *(f"{n}{s}" for n in done for s in (".json", ".txt"))]
    assert sorted(p.name for p in out.iterdir()) == sorted(expected)  # no temporary file
    monkeypatch.undo()
    _interrupt.clear()  # the next run: a new process
    assert _batch(two_videos, out) == 0
    assert _statuses(out) == {n: "skipped" if n in done else "done" for n in ("a", "b")}
    for name in ("a.txt", "b.txt"):
        assert (out / name).read_bytes() == (whole / name).read_bytes()


@pytest.mark.parametrize("console", [True, False])
def test_a_live_runs_abort_is_noted_as_the_console_notes_a_ctrl_c(console: bool) -> None:
    """A live ``track`` run's first Ctrl-C stops it (its outputs are then written: not noted),
    the second aborts it: noted by the ``pftrack`` process, whose handler its own replaced, so
    the outputs are refused if code in C drops that interrupt. A caller's own process (Python's
    handler) notes nothing."""
    import signal

    from pftrack._console import _on_sigint
    from pftrack.cli.track import _StopOnCtrlC

    class Source:
        stopped = False

        def stop(self) -> None:
            self.stopped = True

    before = signal.signal(signal.SIGINT, _on_sigint if console else signal.default_int_handler)
    try:
        source = Source()
        with pytest.raises(KeyboardInterrupt), _StopOnCtrlC(source):
            signal.raise_signal(signal.SIGINT)  # the first: stop after this frame
            assert source.stopped and not _interrupt.interrupted()
            signal.raise_signal(signal.SIGINT)  # the second: abort
            for _ in range(1000):  # Python runs the handler between bytecodes
                pass
        assert _interrupt.interrupted() == console
    finally:
        signal.signal(signal.SIGINT, before)


def test_eval_writes_both_its_files_or_neither(
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A Ctrl-C dropped once ``--json`` is written, while ``--csv`` is made: was, ``--json``
    replaced, ``--csv`` refused, and "no output was changed" said; now both are staged."""
    import pftrack.eval.sequences as sequences

    real = sequences.scores_csv

    def dropped_then_csv(*args: Any, **kwargs: Any) -> str:
        _interrupt.remember()
        return real(*args, **kwargs)

    monkeypatch.setattr(sequences, "scores_csv", dropped_then_csv)
    for name in ("e.json", "e.csv"):
        _write_earlier(tmp_path / name)
    argv = COMMANDS["eval"][1](inputs, tmp_path)
    assert main(["-q", *argv]) == 130
    assert capsys.readouterr().err == _said("eval")
    assert _snapshot(tmp_path) == {"e.json": earlier_bytes(".json"), "e.csv": earlier_bytes(".csv")}


@pytest.mark.parametrize("command", ["eval", "experiment"])
def test_a_ctrl_c_once_the_outputs_are_in_place_is_ignored(
    command: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """As for ``track``: a Ctrl-C while the report is printed, the files written, ended the
    run with exit status 130 and "no output was changed"; now it finishes (status 0)."""
    import importlib
    import signal

    names, argv = COMMANDS[command]
    where = importlib.import_module(
        "pftrack.cli.evaluate" if command == "eval" else "pftrack.cli.experiment"
    )
    stream = where.report_stream  # called as the report is printed, the files in place

    def ctrl_c_then_stream(*args: Any) -> Any:
        signal.raise_signal(signal.SIGINT)
        return stream(*args)

    monkeypatch.setattr(where, "report_stream", ctrl_c_then_stream)
    assert main(["-q", *argv(inputs, tmp_path)]) == 0, capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)


def _signal_after_renaming(
    monkeypatch: pytest.MonkeyPatch, signum: int, targets: set[Path]
) -> list[str]:
    """``os.replace`` renames, then sends `signum` to the process after the first rename onto
    one of `targets` (a real Ctrl-C, or ``kill``, between two renames of one commit).

    A writer's own renames (the video's ``..v.<hex>.<hex>.mp4`` onto its staged file) pass.
    Returns the names of the targets renamed onto.
    """
    import os

    real, renamed = os.replace, []

    def replace_then_signal(src: Any, dst: Any) -> None:
        real(src, dst)
        if Path(dst) in targets:
            renamed.append(Path(dst).name)
            if len(renamed) == 1:
                os.kill(os.getpid(), signum)
                for _ in range(1000):  # Python runs the handler between bytecodes
                    pass

    monkeypatch.setattr(os, "replace", replace_then_signal)
    return renamed


@pytest.mark.filterwarnings("ignore::UserWarning")  # a 20-frame scene's notes, not the subject
@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("command", [c for c in sorted(COMMANDS) if len(COMMANDS[c][0]) > 1])
def test_a_signal_between_the_renames_leaves_every_output_new(
    command: str,
    signame: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Every command that puts several files in place: a Ctrl-C (SIGTERM) after the first is
    renamed, before the others, leaves them all new and no temporary file. These commands
    ignore interrupts once their work is done (``hold_interrupts``): they finish, status 0."""
    import signal

    names, argv = COMMANDS[command]
    for name in names:
        _write_earlier(tmp_path / name)
    earlier = _snapshot(tmp_path)
    renamed = _signal_after_renaming(
        monkeypatch, getattr(signal, signame), {tmp_path / n for n in names}
    )
    assert main(["-q", *argv(inputs, tmp_path)]) == 0, capsys.readouterr().err
    monkeypatch.undo()
    assert sorted(renamed) == sorted(names)
    snapshot = _snapshot(tmp_path)
    assert sorted(snapshot) == sorted(names)  # no temporary file
    assert all(snapshot[name] != earlier[name] for name in names)


@pytest.mark.filterwarnings("ignore:no track over 5 frames")  # 5 frames: no track confirmed
@pytest.mark.parametrize(
    ("signame", "status", "said"),
    [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "terminated (SIGTERM)")],
)
def test_a_demo_signalled_between_its_renames_leaves_every_file_new(
    signame: str,
    status: int,
    said: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A real Ctrl-C (SIGTERM) after the first of ``demo``'s files is renamed into place: the
    interrupt is raised after the last, so all five are the new run's (its record vouches for
    each) and the message says they were written. Was: the ``KeyboardInterrupt`` raised between
    two renames left ``tracks.txt`` new beside the earlier demo's video, plot and record, and
    said "no output was changed"."""
    import hashlib
    import signal

    from pftrack.demo import OUTPUTS, RECORD

    out_dir = tmp_path / "d"
    assert main(["-q", "demo", "--out-dir", str(out_dir), "--frames", "5"]) == 0
    earlier = _snapshot(out_dir)
    capsys.readouterr()
    names = [*OUTPUTS, RECORD]
    renamed = _signal_after_renaming(
        monkeypatch, getattr(signal, signame), {out_dir / n for n in names}
    )
    argv = ["-q", "demo", "--out-dir", str(out_dir), "--frames", "5", "--seed", "1"]
    assert main(argv) == status
    monkeypatch.undo()
    assert capsys.readouterr().err == (
        f"pftrack demo: {said}; the outputs were written before it: {out_dir}/tracks.txt, "
        "truth.txt, annotated.mp4, trajectories.png\n"
    )
    assert sorted(renamed) == sorted(names)
    now = _snapshot(out_dir)
    assert sorted(now) == sorted(names)  # no temporary file
    record = json.loads((out_dir / RECORD).read_text())
    assert record == {n: hashlib.sha256(now[n] or b"").hexdigest() for n in OUTPUTS}
    assert now["truth.txt"] != earlier["truth.txt"] and now[RECORD] != earlier[RECORD]


@pytest.mark.filterwarnings("ignore::UserWarning")  # 10-frame scenes: few tracks confirmed
def test_a_batch_signalled_between_a_sequences_renames_writes_it_whole(
    two_videos: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A real Ctrl-C after a sequence's ``NAME.txt`` is renamed into place, before its sidecar:
    raised once the sidecar is in place too, so the sequence is finished (``done``, in
    ``summary.json`` as in its sidecar) and the batch stops there. Was: ``a.txt`` replaced, the
    sidecar left saying ``writing``, the sequence listed ``cancelled``."""
    import signal

    whole = tmp_path / "whole"
    assert _batch(two_videos, whole) == 0
    out = tmp_path / "out"
    renamed = _signal_after_renaming(monkeypatch, signal.SIGINT, {out / "a.txt"})
    capsys.readouterr()
    assert _batch(two_videos, out) == 130
    monkeypatch.undo()
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == (
        "pftrack batch: interrupted; the outputs of the 1 sequence finished are written and "
        f"complete; {out}/summary.json lists the rest as cancelled (re-run to finish them)"
    )
    assert renamed == ["a.txt"]
    assert _statuses(out) == {"a": "done", "b": "cancelled"}
    assert json.loads((out / "a.json").read_text())["status"] == "done"
    assert sorted(p.name for p in out.iterdir()) == ["a.json", "a.txt", "summary.json"]
    assert (out / "a.txt").read_bytes() == (whole / "a.txt").read_bytes()
    assert _batch(two_videos, out) == 0  # a re-run skips a and makes b
    assert _statuses(out) == {"a": "skipped", "b": "done"}


def _folder_at_the_second_rename(monkeypatch: pytest.MonkeyPatch, targets: set[Path]) -> list[str]:
    """``os.replace`` onto the second of `targets` renamed onto first puts a folder in its place
    (as if a user or a program had made one there while the run went on).

    Returns the names of the targets renamed onto (the writers' own renames pass).
    """
    import os

    real, renamed = os.replace, []

    def replace(src: Any, dst: Any) -> None:
        if Path(dst) in targets:
            renamed.append(Path(dst).name)
            if len(renamed) == 2 and not Path(dst).is_dir():
                Path(dst).unlink()
                Path(dst).mkdir()
        real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    return renamed


@pytest.mark.filterwarnings("ignore::UserWarning")  # a 20-frame scene's notes, not the subject
def test_track_whose_second_rename_fails_puts_the_first_output_back(
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``track --out t.txt --render v.mp4``: a folder in place of the second output renamed
    fails the run and the first keeps the earlier run's bytes and mode. Was: the first stayed
    new beside the earlier video, the user's old tracks gone. A backup an earlier run's
    ``kill -9`` left is neither read nor touched."""
    import os
    import stat

    out, video = tmp_path / "t.txt", tmp_path / "v.mp4"
    for path in (out, video):
        _write_earlier(path)
        path.chmod(0o600)
    earlier = _snapshot(tmp_path)
    stale = tmp_path / ".t.txt.0123456789ab.old"
    stale.write_bytes(b"older")
    renamed = _folder_at_the_second_rename(monkeypatch, {out, video})
    argv = ["-q", "track", str(inputs["video"]), "--out", str(out), "--render", str(video),
            "--particles", "20"]  # fmt: skip
    assert main(argv) == 2
    monkeypatch.undo()
    first, second = (tmp_path / n for n in renamed[:2])
    assert first.read_bytes() == earlier[first.name]
    assert stat.S_IMODE(os.stat(first).st_mode) == 0o600
    assert capsys.readouterr().err == (
        f"pftrack track: error: cannot replace output {second} (Is a directory); no output file "
        "was changed\n"
    )
    assert second.is_dir() and stale.read_bytes() == b"older"
    assert sorted(p.name for p in tmp_path.iterdir()) == [stale.name, "t.txt", "v.mp4"]


@pytest.mark.filterwarnings("ignore::UserWarning")  # 10-frame scenes: few tracks confirmed
def test_a_batch_sequence_whose_rename_fails_keeps_its_earlier_outputs(
    two_videos: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A folder put in place of ``a.mp4`` as a's outputs are renamed: a fails (its error names
    ``a.mp4``), ``a.txt`` keeps the earlier bytes, its sidecar says ``writing``, b goes on
    (skipped: done by the first run); a re-run once the folder is gone makes a. Was: ``a.txt``
    new beside the old video."""
    out = tmp_path / "out"
    argv = ["-q", "batch", str(two_videos), "--out", str(out), "--workers", "0",
            "--particles", "20", "--render"]  # fmt: skip
    assert main(argv) == 0
    # changed since: a is made again. a.mp4 another of pftrack's videos (b's render): a file
    # that is not one is refused before any work since stop 70, as --render refuses it
    (out / "a.txt").write_bytes(EARLIER)
    (out / "a.mp4").write_bytes((out / "b.mp4").read_bytes())
    renamed = _folder_at_the_second_rename(monkeypatch, {out / "a.txt", out / "a.mp4"})
    capsys.readouterr()
    status = main(argv)
    monkeypatch.undo()
    assert status == 1, capsys.readouterr().err
    assert renamed[:2] == ["a.txt", "a.mp4"]
    summary = {e["name"]: e for e in json.loads((out / "summary.json").read_text())["sequences"]}
    assert summary["a"]["status"] == "failed" and summary["b"]["status"] == "skipped"
    assert (out / "a.txt").read_bytes() == EARLIER and (out / "a.mp4").is_dir()
    assert summary["a"]["error"] == (
        f"writing its outputs: cannot replace output {out / 'a.mp4'} (Is a directory); no "
        "output file was changed"
    )
    assert json.loads((out / "a.json").read_text())["status"] == "writing"
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]  # no backup left
    (out / "a.mp4").rmdir()
    assert main(argv) == 0
    assert _statuses(out) == {"a": "done", "b": "skipped"}


def _runs_later(done: Callable[[], bool]) -> None:
    """Run lines until `done()` (a handler put off ran: its timer is 2 ms), or fail after 5 s."""
    import time

    end = time.monotonic() + 5.0
    while not done():
        if time.monotonic() > end:
            pytest.fail("the signal put off never ran its handler")
        time.sleep(0.001)


def test_a_ctrl_c_inside_importlib_is_raised_on_the_next_line_outside_it() -> None:
    """The console's handler, called in importlib's frozen frames, raises nothing there: C that
    imports (an extension's init: OpenCV's import_array) printed the KeyboardInterrupt raised
    into it as a traceback (``File "<frozen importlib._bootstrap>", line 216, in
    _lock_unlock_module``, then ``pftrack recover: interrupted``: CI, 7 December). It notes
    the interrupt and raises the signal again, so the next line outside raises it."""
    import signal
    import sys
    import types

    from pftrack._console import _on_sigint

    importlib_code = compile("pass", "<frozen importlib._bootstrap>", "exec")
    inside = types.SimpleNamespace(f_code=importlib_code)
    seen: list[int] = []
    where: list[str] = []

    def handler(signum: int, frame: Any) -> None:
        seen.append(signum)
        where.append(frame.f_code.co_name)

    alarm = signal.getsignal(signal.SIGALRM)
    before = signal.signal(signal.SIGINT, handler)
    try:
        try:
            _on_sigint(signal.SIGINT, inside)
        except KeyboardInterrupt:
            pytest.fail("raised inside importlib's frames")  # was: raised here
        _runs_later(lambda: seen == [signal.SIGINT])  # its handler, from the timer
        # at a line of the test, not inside the handler's own call (was: signal.raise_signal ran
        # it there, put_off_in_imports's frame, still under importlib's: CI, 7 December)
        assert where[0] not in {"put_off_in_imports", "_on_sigint"}, where
        assert _interrupt.interrupted()
        signal.signal(signal.SIGINT, _on_sigint)  # the console's: it raises on a line outside
        with pytest.raises(KeyboardInterrupt):
            _on_sigint(signal.SIGINT, inside)
            _runs_later(lambda: False)
        assert signal.getsignal(signal.SIGALRM) is alarm  # set back
        with pytest.raises(KeyboardInterrupt):  # anywhere else: at once
            _on_sigint(signal.SIGINT, sys._getframe())
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_sigterm_inside_importlib_is_raised_on_the_next_line_outside_it() -> None:
    """The command's SIGTERM handler (``pftrack.cli._signals``, set while a command runs) did
    what the console's SIGINT handler did before 3a412e73: it raised ``Terminated`` inside
    importlib's frozen frames, where C that imports (a late ``import cv2`` in a command's
    body) prints it as a traceback. Now it raises the signal again, and the next line outside
    them raises it; its handler is not yet set to ignore (that is the raise's)."""
    import signal
    import sys
    import types

    from pftrack.cli._signals import Terminated, _raise_terminated

    inside = types.SimpleNamespace(f_code=compile("pass", "<frozen importlib._bootstrap>", "exec"))
    seen: list[int] = []
    before = signal.signal(signal.SIGTERM, lambda signum, frame: seen.append(signum))
    try:
        try:
            _raise_terminated(signal.SIGTERM, inside)
        except Terminated:
            pytest.fail("raised inside importlib's frames")  # was: raised here
        _runs_later(lambda: seen == [signal.SIGTERM])  # its handler, from the timer
        signal.signal(signal.SIGTERM, _raise_terminated)
        with pytest.raises(Terminated):
            _raise_terminated(signal.SIGTERM, inside)
            _runs_later(lambda: False)
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN  # once, as ever
        signal.signal(signal.SIGTERM, _raise_terminated)
        with pytest.raises(Terminated):  # anywhere else: at once
            _raise_terminated(signal.SIGTERM, sys._getframe())
    finally:
        signal.signal(signal.SIGTERM, before)


def test_a_second_ctrl_c_of_a_stopping_track_inside_importlib_waits_for_the_next_line() -> None:
    """``pftrack track``'s live handler: a second Ctrl-C aborts with ``KeyboardInterrupt``;
    inside importlib's frames it is raised again instead, as the console's handler does."""
    import signal
    import sys
    import types

    from pftrack.cli.track import _StopOnCtrlC

    inside = types.SimpleNamespace(f_code=compile("pass", "<frozen importlib._bootstrap>", "exec"))
    seen: list[int] = []
    stopping = _StopOnCtrlC(types.SimpleNamespace(stopped=True))
    before = signal.signal(signal.SIGINT, lambda signum, frame: seen.append(signum))
    try:
        try:
            stopping._handler(signal.SIGINT, inside)
        except KeyboardInterrupt:
            pytest.fail("raised inside importlib's frames")  # was: raised here
        _runs_later(lambda: seen == [signal.SIGINT])
        with pytest.raises(KeyboardInterrupt):  # anywhere else: at once
            stopping._handler(signal.SIGINT, sys._getframe())
    finally:
        signal.signal(signal.SIGINT, before)
