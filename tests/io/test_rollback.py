"""A rename of :func:`~pftrack.io.atomic.staged_outputs` that fails puts every output back.

Was: the targets renamed before the one that failed stayed new, their earlier contents lost (a
user's old tracks replaced, the video beside them not). Each existing target is now kept under
a hidden backup (``.NAME.<hex>.old``, a hard link; where the file system makes none, the target
itself moved there) until every rename is done. Every test runs with hard links and without
(``os.link`` refused, as on a vfat stick).
"""

from __future__ import annotations

import errno
import itertools
import os
import re
import signal
import stat
from pathlib import Path

import pytest

from pftrack.io.atomic import staged_outputs


@pytest.fixture(params=["links", "no links"])
def links(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Hard links as this file system makes them, or none (``EPERM``)."""
    if request.param == "no links":

        def refuse(*args: object, **kwargs: object) -> None:
            raise PermissionError(errno.EPERM, os.strerror(errno.EPERM))

        monkeypatch.setattr(os, "link", refuse)
    return str(request.param)


def _names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def _failed(target: Path) -> str:
    """The whole message of a commit that failed at `target` and put everything back."""
    name = re.escape(str(target))
    return rf"^cannot replace output {name} \(Is a directory\); no output file was changed$"


def _folder_at_the_rename(monkeypatch: pytest.MonkeyPatch, target: Path) -> None:
    """``os.replace`` onto `target` first puts a folder in its place (after the backups)."""
    real = os.replace

    def replace(src: str, dst: str) -> None:
        if Path(dst) == target and not target.is_dir():
            if os.path.lexists(target):
                target.unlink()
            target.mkdir()
        real(src, dst)

    monkeypatch.setattr(os, "replace", replace)


def test_a_folder_in_the_second_targets_place_puts_the_first_back(
    tmp_path: Path, links: str
) -> None:
    """The first target keeps its earlier file (bytes, mode, the file itself); no backup left."""
    a, b = tmp_path / "a.txt", tmp_path / "b.mp4"
    a.write_bytes(b"old a")
    a.chmod(0o600)
    b.write_bytes(b"old b")
    inode = a.stat().st_ino
    with pytest.raises(IsADirectoryError, match=_failed(b)) as exc, staged_outputs() as stage:
        stage(a).write_bytes(b"new a")
        stage(b).write_bytes(b"new b")
        b.unlink()  # between staging and the renames: a folder put in b's place
        b.mkdir()
    assert exc.value.errno == errno.EISDIR
    assert a.read_bytes() == b"old a" and stat.S_IMODE(a.stat().st_mode) == 0o600
    assert a.stat().st_ino == inode  # the earlier file itself, not a copy
    assert _names(tmp_path) == ["a.txt", "b.mp4"]  # no backup, no temporary file
    assert b.is_dir() and not any(b.iterdir())


def test_a_target_that_did_not_exist_is_removed_again(tmp_path: Path, links: str) -> None:
    a, b, c = tmp_path / "a.txt", tmp_path / "b.mp4", tmp_path / "c.png"
    b.write_bytes(b"old b")
    c.write_bytes(b"old c")
    with pytest.raises(IsADirectoryError, match=_failed(b)), staged_outputs() as stage:
        stage(c).write_bytes(b"new c")
        stage(a).write_bytes(b"new a")  # a new output
        stage(b).write_bytes(b"new b")
        b.unlink()
        b.mkdir()
    assert _names(tmp_path) == ["b.mp4", "c.png"]
    assert c.read_bytes() == b"old c"


def test_a_folder_put_in_place_during_the_renames(
    tmp_path: Path, links: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """After the backups were made: with a hard link, b's backup is dropped (b is the folder's
    now); moved to its backup (no links), b's earlier file cannot go back, and is kept there,
    named by the message."""
    a, b = tmp_path / "a.txt", tmp_path / "b.mp4"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    _folder_at_the_rename(monkeypatch, b)
    with pytest.raises(IsADirectoryError) as exc, staged_outputs() as stage:
        stage(a).write_bytes(b"new a")
        stage(b).write_bytes(b"new b")
    monkeypatch.undo()
    assert a.read_bytes() == b"old a" and b.is_dir()
    if links == "links":
        assert re.match(_failed(b), str(exc.value))
        assert _names(tmp_path) == ["a.txt", "b.mp4"]
    else:
        (kept,) = set(_names(tmp_path)) - {"a.txt", "b.mp4"}
        assert kept.startswith(".b.mp4.") and kept.endswith(".old")
        assert (tmp_path / kept).read_bytes() == b"old b"
        assert str(exc.value) == (
            f"cannot replace output {b} (Is a directory); every output file was put back but "
            f"{b}, whose earlier contents are kept in {tmp_path / kept}"
        )


def test_a_symbolic_links_file_is_put_back(tmp_path: Path, links: str) -> None:
    real, a, b = tmp_path / "real.txt", tmp_path / "a.txt", tmp_path / "b.mp4"
    real.write_bytes(b"old a")
    a.symlink_to("real.txt")
    with pytest.raises(IsADirectoryError, match=_failed(b)), staged_outputs() as stage:
        stage(a).write_bytes(b"new a")
        stage(b).write_bytes(b"new b")
        b.mkdir()
    assert a.is_symlink() and os.readlink(a) == "real.txt" and real.read_bytes() == b"old a"
    assert _names(tmp_path) == ["a.txt", "b.mp4", "real.txt"]


def test_the_backups_are_removed_once_every_target_is_new(tmp_path: Path, links: str) -> None:
    a, b = tmp_path / "a.txt", tmp_path / "b.mp4"
    a.write_bytes(b"old a")
    a.chmod(0o600)
    with staged_outputs() as stage:
        stage(a).write_bytes(b"new a")
        stage(b).write_bytes(b"new b")
    assert (a.read_bytes(), b.read_bytes()) == (b"new a", b"new b")
    assert stat.S_IMODE(a.stat().st_mode) == 0o600  # the mode of the file it replaced
    assert _names(tmp_path) == ["a.txt", "b.mp4"]


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="signals cannot be blocked")
@pytest.mark.parametrize("fails", [False, True])
def test_a_ctrl_c_during_the_renames_leaves_no_backup(
    tmp_path: Path, links: str, monkeypatch: pytest.MonkeyPatch, fails: bool
) -> None:
    """A Ctrl-C after the first rename waits for the step's end: the targets are all new, or
    (a later rename failed) all as they were, and no backup is left either way."""
    a, b = tmp_path / "a.txt", tmp_path / "b.mp4"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real = os.replace

    def replace_then_signal(src: str, dst: str) -> None:
        real(src, dst)
        if Path(dst) == a:
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(1000):  # Python runs a handler between bytecodes
                pass

    monkeypatch.setattr(os, "replace", replace_then_signal)
    with pytest.raises(KeyboardInterrupt), staged_outputs() as stage:
        stage(a).write_bytes(b"new a")
        stage(b).write_bytes(b"new b")
        if fails:
            b.unlink()
            b.mkdir()
    monkeypatch.undo()
    assert a.read_bytes() == (b"old a" if fails else b"new a")
    assert b.is_dir() if fails else b.read_bytes() == b"new b"
    assert _names(tmp_path) == ["a.txt", "b.mp4"]


def test_a_backup_a_kill_left_is_neither_read_nor_touched(
    tmp_path: Path, links: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A ``kill -9`` during the renames can leave ``.NAME.<hex>.old``; the next run picks
    another name (here the same one first), says it is there, and leaves that file alone."""
    from pftrack.io import atomic

    a = tmp_path / "a.txt"
    a.write_bytes(b"old a")
    stale = tmp_path / f".a.txt.{0:012x}.old"
    stale.write_bytes(b"older a")
    tokens = itertools.chain([f"{0:012x}"] * 2, (f"{k:012x}" for k in itertools.count(1)))
    monkeypatch.setattr(atomic.secrets, "token_hex", lambda n: next(tokens))
    with (
        pytest.warns(UserWarning, match=f"{re.escape(stale.name)} was left by"),
        staged_outputs() as stage,
    ):
        stage(a).write_bytes(b"new a")
    assert a.read_bytes() == b"new a" and stale.read_bytes() == b"older a"
    assert _names(tmp_path) == [stale.name, "a.txt"]


def test_a_pipe_gets_nothing_when_a_rename_fails(tmp_path: Path, links: str) -> None:
    """A FIFO is written after the renames (module notes): after a failed one, never."""
    a, b, fifo = tmp_path / "a.txt", tmp_path / "b.mp4", tmp_path / "fifo"
    a.write_bytes(b"old a")
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # the writer's open does not wait
    try:
        with pytest.raises(IsADirectoryError, match=_failed(b)), staged_outputs() as stage:
            stage(fifo).write_bytes(b"rows")
            stage(a).write_bytes(b"new a")
            stage(b).write_bytes(b"new b")
            b.mkdir()
        assert os.read(reader, 100) == b""
    finally:
        os.close(reader)
    assert a.read_bytes() == b"old a" and _names(tmp_path) == ["a.txt", "b.mp4", "fifo"]
