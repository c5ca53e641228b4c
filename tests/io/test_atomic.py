"""Atomic outputs: all or nothing, and created with the user's umask."""

from __future__ import annotations

import errno
import os
import signal
import stat
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from pftrack.io.atomic import atomic_path, atomic_write
from pftrack.io.mot import write_mot


@pytest.fixture
def umask():
    """Set the process umask for one test, then restore it."""
    old = os.umask(0o022)
    os.umask(old)

    def set_mask(mask: int) -> None:
        os.umask(mask)

    yield set_mask
    os.umask(old)


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_outputs_follow_the_umask(tmp_path: Path, umask, mask: int) -> None:
    umask(mask)
    write_mot(tmp_path / "t.txt", [[1, 1, 0, 0, 10, 10]])
    with atomic_path(tmp_path / "p.bin") as tmp:
        tmp.write_bytes(b"x")
    for name in ("t.txt", "p.bin"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o666 & ~mask, name


def test_failed_write_keeps_the_old_file_and_leaves_nothing(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    target.write_text("old\n")
    with pytest.raises(RuntimeError), atomic_write(target) as fh:
        fh.write("new, half")
        raise RuntimeError("crash in the middle")
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_empty_atomic_path_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(OSError, match="nothing was written"), atomic_path(tmp_path / "v.mp4"):
        pass
    assert not any(tmp_path.iterdir())


def test_missing_folder_is_named(tmp_path: Path) -> None:
    with (
        pytest.raises(FileNotFoundError, match="missing"),
        atomic_write(tmp_path / "missing" / "x"),
    ):
        pass


def test_staged_outputs_replace_all_or_none(tmp_path: Path, umask) -> None:
    from pftrack.io.atomic import staged_outputs

    umask(0o022)
    a, b = tmp_path / "a.txt", tmp_path / "b.png"
    a.write_text("old a")
    b.write_text("old b")
    with pytest.raises(KeyboardInterrupt), staged_outputs() as stage:
        write_mot(stage(a), [[1, 1, 0, 0, 10, 10]])
        stage(b).write_bytes(b"half")
        raise KeyboardInterrupt
    assert (a.read_text(), b.read_text()) == ("old a", "old b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.png"]
    with staged_outputs() as stage:
        write_mot(stage(a), [[1, 1, 0, 0, 10, 10]])
        stage(b).write_bytes(b"new")
    assert a.read_text().startswith("1,1,0,0,10,10") and b.read_bytes() == b"new"
    assert {stat.S_IMODE(p.stat().st_mode) for p in (a, b)} == {0o644}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.png"]


def test_staged_outputs_remove_a_writers_own_temporary_file(tmp_path: Path) -> None:
    """A writer stopped after making its temporary file beside a staged one, before anyone held
    it (SIGTERM in ``VideoWriter.__init__``): was left behind, ``..v.<hex>.<hex>.mp4``."""
    from pftrack.io.atomic import staged_outputs

    (tmp_path / "v.mp4").write_bytes(b"old")
    (tmp_path / ".v.keep.mp4").write_bytes(b"not ours")
    with pytest.raises(KeyboardInterrupt), staged_outputs() as stage:
        held = atomic_path(stage(tmp_path / "v.mp4"))  # entered, never left (kept alive here:
        held.__enter__()  # a collected generator would clean up after itself)
        assert len(list(tmp_path.iterdir())) == 4
        raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == [".v.keep.mp4", "v.mp4"]


def _signalled_after_the_first_rename(
    monkeypatch: pytest.MonkeyPatch, signum: int, sender: str
) -> list[str]:
    """``os.replace`` renames, then (after the first rename only) sends `signum` to the process.

    `sender`: ``"main"`` (``os.kill`` in this thread, whose handler then runs at once) or
    ``"thread"`` (``os.kill`` from another thread, which takes the signal when this one blocks
    it: Python then runs the handler here at the next chance). Returns the targets renamed.
    """
    real, renamed = os.replace, []

    def replace_then_signal(src: str, dst: str) -> None:
        real(src, dst)
        renamed.append(os.path.basename(dst))
        if len(renamed) == 1:
            if sender == "main":
                os.kill(os.getpid(), signum)
            else:
                killer = threading.Thread(target=os.kill, args=(os.getpid(), signum))
                killer.start()
                killer.join()
            for _ in range(1000):  # Python runs a handler between bytecodes
                pass

    monkeypatch.setattr(os, "replace", replace_then_signal)
    return renamed


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="signals cannot be blocked")
@pytest.mark.parametrize("sender", ["main", "thread"])
@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
def test_a_signal_during_the_renames_is_raised_after_the_last(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, signame: str, sender: str
) -> None:
    """Ctrl-C (SIGTERM under ``pftrack``) between two renames of :func:`staged_outputs`: every
    target new, no temporary file, the interrupt raised after; ``on_commit`` called before it.

    Was: the ``KeyboardInterrupt`` raised after the first rename left ``a.txt`` new beside an old
    ``b.png`` and ``c.json`` (``pftrack demo``'s five files, a real Ctrl-C).
    """
    names = ["a.txt", "b.png", "c.json"]
    for name in names:
        (tmp_path / name).write_text(f"old {name}")
    signum = getattr(signal, signame)
    # Python's own SIGINT handler, as in a shell's foreground: a suite started with `&` or
    # nohup starts with SIGINT ignored, and a deferred SIGINT then stays ignored (as it should)
    started = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _raised_after_the_last(tmp_path, monkeypatch, names, signum, sender)
    finally:
        signal.signal(signal.SIGINT, started)


def _raised_after_the_last(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, names: list[str], signum: int, sender: str
) -> None:
    from pftrack.cli._signals import sigterm_raises
    from pftrack.io.atomic import staged_outputs

    renamed = _signalled_after_the_first_rename(monkeypatch, signum, sender)
    committed: list[list[str]] = []
    with pytest.raises(KeyboardInterrupt), sigterm_raises():
        with staged_outputs(on_commit=lambda: committed.append(list(renamed))) as stage:
            for name in names:
                stage(tmp_path / name).write_text(f"new {name}")
        for _ in range(1000):
            pass
    monkeypatch.undo()
    assert [(tmp_path / name).read_text() for name in names] == [f"new {n}" for n in names]
    assert sorted(p.name for p in tmp_path.iterdir()) == names  # no temporary file
    assert committed == [names]  # told once all three were in place, before the interrupt
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # handlers restored


def test_interrupts_deferred_raises_nothing_when_none_came() -> None:
    from pftrack.io.atomic import interrupts_deferred

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    with interrupts_deferred():
        pass
    assert {s: signal.getsignal(s) for s in before} == before
    assert not signal.pthread_sigmask(signal.SIG_BLOCK, [])


def _write_through(writer: str, target: Path, text: str) -> None:
    """Write `text` to `target` with `writer`: atomic_write, atomic_path or staged_outputs."""
    from pftrack.io.atomic import staged_outputs

    if writer == "atomic_write":
        with atomic_write(target) as fh:
            fh.write(text)
    elif writer == "atomic_path":
        with atomic_path(target) as tmp:
            tmp.write_text(text)
    else:
        assert writer == "staged_outputs", writer
        with staged_outputs() as stage:
            stage(target).write_text(text)


def _interrupted_as_created(monkeypatch: pytest.MonkeyPatch, folder: Path) -> None:
    """``os.open`` creates the file in `folder`, then a Ctrl-C is raised before it returns.

    As Python raises a signal's ``KeyboardInterrupt`` once a call returns, before its result
    is stored: the file exists, and the writer has not got its name or descriptor.
    """
    real = os.open

    def open_then_interrupted(path: str, flags: int, mode: int = 0o777) -> int:
        fd = real(path, flags, mode)
        if os.path.dirname(os.fsdecode(path)) == str(folder):
            os.close(fd)
            raise KeyboardInterrupt
        return fd

    monkeypatch.setattr(os, "open", open_then_interrupted)


@pytest.mark.parametrize("writer", ["atomic_write", "atomic_path", "staged_outputs", "check"])
def test_a_signal_as_the_temporary_file_is_created_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, writer: str
) -> None:
    """Was: the file made between its creation and the writer's try was left behind
    (``.out.<hex>.txt``; ``staged_outputs`` too, whose clean-up had not listed it yet)."""
    from pftrack.io.atomic import check_output

    target = tmp_path / "out.txt"
    target.write_text("old\n")
    (tmp_path / ".out.keep.txt").write_text("not ours\n")
    _interrupted_as_created(monkeypatch, tmp_path)
    with pytest.raises(KeyboardInterrupt):
        if writer == "check":  # the writable-folder probe of check_output
            check_output(target)
        else:
            _write_through(writer, target, "new\n")
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == [".out.keep.txt", "out.txt"]
    assert target.read_text() == "old\n"


def test_an_interrupt_while_removing_still_removes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An interrupt raised as a temporary file is removed: the file goes, the interrupt follows.

    Was: ``kill`` sent as ``pftrack track`` checked its output folder left its probe file
    (``.t.txt.<hex>.probe``; CI at load 8).
    """
    from pftrack.io.atomic import _remove

    files = [tmp_path / "a.tmp", tmp_path / "b.tmp"]
    for f in files:
        f.write_text("x")
    unlink, calls = os.unlink, []

    def interrupted_first(path: str) -> None:
        calls.append(path)
        if len(calls) == 1:
            raise KeyboardInterrupt  # before it removed anything
        unlink(path)

    monkeypatch.setattr(os, "unlink", interrupted_first)
    with pytest.raises(KeyboardInterrupt):
        _remove([str(f) for f in files])
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="signals cannot be blocked")
def test_a_signal_during_the_output_check_leaves_no_probe(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGINT sent while the folder's probe file exists: raised once the probe is gone."""
    from pftrack.io.atomic import check_output

    unlink = os.unlink

    def signalled_then_unlink(path: str) -> None:
        if path.endswith(".probe"):  # the probe made, not yet removed
            signal.raise_signal(signal.SIGINT)  # Python's handler raises KeyboardInterrupt
        unlink(path)

    monkeypatch.setattr(os, "unlink", signalled_then_unlink)
    with pytest.raises(KeyboardInterrupt):
        check_output(tmp_path / "t.txt")
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="signals cannot be blocked")
def test_a_signal_during_the_output_folder_check_leaves_no_probe_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same for an output folder's probe (a folder made and removed): was left behind."""
    from pftrack.io.atomic import check_output_folder

    rmdir = os.rmdir

    def signalled_then_rmdir(path: str) -> None:
        if ".pftrack-probe-" in str(path):  # the probe made, not yet removed
            signal.raise_signal(signal.SIGINT)
        rmdir(path)

    monkeypatch.setattr(os, "rmdir", signalled_then_rmdir)
    with pytest.raises(KeyboardInterrupt):
        check_output_folder(tmp_path / "out", "--out")
    monkeypatch.undo()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("mode", [0o600, 0o640])
def test_replacing_a_file_keeps_its_permissions(tmp_path: Path, umask, mode: int) -> None:
    """A file the user restricted stays restricted: not reset to the umask's 0o644."""
    from pftrack.io.atomic import staged_outputs

    umask(0o022)
    names = ("t.txt", "p.bin", "s.txt", "v.avi")
    for name in names:
        (tmp_path / name).write_text("old")
        os.chmod(tmp_path / name, mode)
    with atomic_write(tmp_path / "t.txt") as fh:
        assert stat.S_IMODE(os.fstat(fh.fileno()).st_mode) == mode  # never wider, even mid-write
        fh.write("new")
    with atomic_path(tmp_path / "p.bin") as tmp:
        tmp.unlink()  # a writer that makes its file anew (umask default) still gets `mode`
        tmp.write_bytes(b"new")
    with staged_outputs() as stage:
        stage(tmp_path / "s.txt").write_text("new")
        stage(tmp_path / "v.avi").write_bytes(b"new")
    for name in names:
        assert (tmp_path / name).read_bytes() == b"new", name
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == mode, name


def test_a_new_file_still_follows_the_umask(tmp_path: Path, umask) -> None:
    umask(0o027)
    write_mot(tmp_path / "t.txt", [[1, 1, 0, 0, 10, 10]])
    assert stat.S_IMODE((tmp_path / "t.txt").stat().st_mode) == 0o640


# Outputs that are not plain files (issue: every writer renamed a regular file over them).


def _read_in_thread(fifo: Path) -> tuple[threading.Thread, list[bytes]]:
    """A reader of named pipe `fifo` (a writer's open blocks until one exists)."""
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    return reader, got


def test_a_symlink_output_replaces_its_target_and_stays_a_link(tmp_path: Path) -> None:
    """Was: the link replaced by a regular file, its target left as it was."""
    from pftrack.io.atomic import staged_outputs

    (tmp_path / "real").mkdir()
    names = ("t.txt", "p.bin", "s.txt")
    for name in names:
        (tmp_path / "real" / name).write_text("old")
        (tmp_path / name).symlink_to(Path("real") / name)  # relative, as `ln -s` makes them
        os.chmod(tmp_path / "real" / name, 0o600)
    with atomic_write(tmp_path / "t.txt") as fh:
        fh.write("new")
    with atomic_path(tmp_path / "p.bin") as tmp:
        assert tmp.parent == tmp_path / "real"  # beside the target: the rename is atomic
        tmp.write_bytes(b"new")
    with staged_outputs() as stage:
        stage(tmp_path / "s.txt").write_text("new")
    for name in names:
        assert (tmp_path / name).is_symlink(), name
        assert (tmp_path / "real" / name).read_text() == "new", name
        assert stat.S_IMODE((tmp_path / "real" / name).stat().st_mode) == 0o600, name
    assert sorted(p.name for p in (tmp_path / "real").iterdir()) == sorted(names)


def test_a_dangling_symlink_creates_its_target(tmp_path: Path) -> None:
    (tmp_path / "link.txt").symlink_to("new.txt")
    write_mot(tmp_path / "link.txt", [[1, 1, 0, 0, 10, 10]])
    assert (tmp_path / "link.txt").is_symlink()
    assert (tmp_path / "new.txt").read_text().startswith("1,1,0,0,10,10")


def test_a_symlink_loop_is_an_error(tmp_path: Path) -> None:
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    with pytest.raises(OSError, match="symbolic links"), atomic_write(tmp_path / "a"):
        pass
    from pftrack.io.atomic import check_output

    for suffixes in (None, (".txt",)):  # was: "Too many levels of symbolic links", no option
        message = rf"^--out {tmp_path}/a: Too many levels of symbolic links$"
        with pytest.raises(OSError, match=message):
            check_output(tmp_path / "a", what="--out", suffixes=suffixes)


def test_a_named_pipe_is_written_through_not_replaced(tmp_path: Path) -> None:
    """Was: the pipe replaced by a regular file (its reader waiting forever)."""
    from pftrack.io.atomic import staged_outputs, writes_through

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    assert writes_through(fifo) and not writes_through(tmp_path / "new.txt")
    reader, got = _read_in_thread(fifo)
    write_mot(fifo, [[1, 1, 0, 0, 10, 10]])
    reader.join(10)
    assert got == [b"1,1,0,0,10,10,1,-1,-1,-1\n"]
    reader, got = _read_in_thread(fifo)
    with staged_outputs() as stage:  # a video or plot: the finished file's bytes
        (tmp_path / "link.png").symlink_to(fifo)
        stage(tmp_path / "link.png").write_bytes(b"png bytes")
    reader.join(10)
    assert got == [b"png bytes"]
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo", "link.png"]  # no temporary


def test_a_link_to_dev_null_discards_and_stays(tmp_path: Path) -> None:
    """``--out /dev/null`` discards (was: as root, /dev/null replaced by a regular file)."""
    from pftrack.io.atomic import check_output, staged_outputs

    null = tmp_path / "null.txt"
    null.symlink_to(os.devnull)
    assert check_output(null) == null
    write_mot(null, [[1, 1, 0, 0, 10, 10]])
    with atomic_path(tmp_path / "null.txt") as tmp:
        tmp.write_bytes(b"video")
    with staged_outputs() as stage:
        stage(null).write_bytes(b"video")
    assert null.is_symlink() and os.readlink(null) == os.devnull
    assert stat.S_ISCHR(Path(os.devnull).stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["null.txt"]


def test_a_descriptor_output_writes_through_the_descriptor(tmp_path: Path) -> None:
    """``/dev/stdout`` with stdout redirected to a file: rows, then what was printed after."""
    import subprocess
    import sys

    (tmp_path / "out").symlink_to("/dev/stdout")
    code = (
        "import sys; from pftrack.io.atomic import atomic_write\n"
        "print('before', flush=True)\n"
        "with atomic_write(sys.argv[1]) as fh: fh.write('rows\\n')\n"
        "print('after')\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    with (tmp_path / "captured.txt").open("w") as stdout:
        argv = [sys.executable, "-c", code, str(tmp_path / "out")]
        subprocess.run(argv, stdout=stdout, check=True, timeout=60, env=env)
    assert (tmp_path / "captured.txt").read_text() == "before\nrows\nafter\n"
    assert (tmp_path / "out").is_symlink()


@pytest.mark.parametrize("name", ["newdir/", "./", "a/.", ".."])
def test_a_name_that_can_only_be_a_folder_is_refused(tmp_path: Path, name: str) -> None:
    """Was: ``newdir/`` wrote a file named ``newdir``."""
    from pftrack.io.atomic import check_output, staged_outputs

    target = f"{tmp_path}/{name}"
    with pytest.raises(ValueError, match="folder; give a file name"):
        check_output(target, what="--out")
    with pytest.raises(ValueError, match="names a folder"), atomic_write(target):
        pass
    with pytest.raises(ValueError, match="names a folder"), atomic_path(target):
        pass
    with pytest.raises(ValueError, match="names a folder"), staged_outputs() as stage:
        stage(target)
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize(
    "writer", ["write_mot", "atomic_write", "atomic_path", "staged_outputs", "link"]
)
def test_an_existing_folder_is_refused_before_writing(tmp_path: Path, writer: str) -> None:
    """Was ``IsADirectoryError: [Errno 21] Is a directory: '/x/.io.<hex>.tmp' -> '/x/io'``,
    naming the hidden temporary file, once the file had been written."""

    folder = tmp_path / "io"
    folder.mkdir()
    (folder / "keep.txt").write_text("x")
    target = folder
    if writer == "link":  # a link to a folder is refused as the folder
        target = tmp_path / "link"
        target.symlink_to(folder)
    with pytest.raises(ValueError, match=rf"^output {target} is a folder; give a file name$"):
        if writer in ("write_mot", "link"):
            write_mot(target, [[1, 1, 10, 10, 5, 5]])
        else:
            _write_through(writer, target, "x")
    assert sorted(p.name for p in folder.iterdir()) == ["keep.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["io"] + (["link"] if writer == "link" else [])
    )


def test_dash_is_refused_as_an_output_name(tmp_path: Path, monkeypatch) -> None:
    from pftrack.io.atomic import check_output

    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match=r"^--out -: standard output .* /dev/stdout$"):
        check_output("-", what="--out")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("writer", ["write_mot", "atomic_path"])
@pytest.mark.parametrize(("code", "cls"), [(errno.EROFS, OSError), (errno.EACCES, PermissionError)])
def test_a_temporary_file_that_cannot_be_made_names_the_output(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, writer: str, code: int, cls: type
) -> None:
    """Was ``OSError: [Errno 30] Read-only file system: '/x/.old.txt.f806e9cd1123.tmp'``.

    A read-only file system (or, for a user other than root, a folder without write
    permission), made here by ``os.open`` refusing every file in the folder, as root's
    permissions would not.
    """
    real = os.open

    def refused(path: str, flags: int, mode: int = 0o777) -> int:
        if os.path.dirname(os.fsdecode(path)) == str(tmp_path) and flags & os.O_CREAT:
            raise OSError(code, os.strerror(code), path)
        return real(path, flags, mode)

    target = tmp_path / "old.txt"
    target.write_text("old\n")
    monkeypatch.setattr(os, "open", refused)
    with pytest.raises(OSError) as exc:
        if writer == "write_mot":
            write_mot(target, [[1, 1, 10, 10, 5, 5]])
        else:
            with atomic_path(target) as tmp:
                tmp.write_text("new\n")
    monkeypatch.undo()
    assert type(exc.value) is cls
    assert (exc.value.errno, exc.value.filename) == (code, str(target))
    assert str(exc.value) == f"[Errno {code}] {os.strerror(code)}: '{target}'"
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old.txt"]


def test_a_failed_rename_names_the_output(tmp_path: Path, monkeypatch) -> None:
    """Was the hidden temporary file and the target, ``'/x/.t.<hex>.tmp' -> '/x/t.txt'``."""

    def busy(src: str, dst: str) -> None:
        raise OSError(errno.EBUSY, os.strerror(errno.EBUSY), src, None, dst)

    target = tmp_path / "t.txt"
    target.write_text("old\n")
    monkeypatch.setattr(os, "replace", busy)
    with pytest.raises(OSError) as exc, atomic_write(target) as fh:
        fh.write("new\n")
    monkeypatch.undo()
    assert (exc.value.errno, exc.value.filename, exc.value.filename2) == (
        errno.EBUSY,
        str(target),
        None,
    )
    assert target.read_text() == "old\n" and [p.name for p in tmp_path.iterdir()] == ["t.txt"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a folder without write bits")
def test_a_folder_without_write_permission_names_the_output(tmp_path: Path) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    target = folder / "old.txt"
    target.write_text("old\n")
    folder.chmod(0o555)
    try:
        with pytest.raises(PermissionError) as exc:
            write_mot(target, [[1, 1, 10, 10, 5, 5]])
    finally:
        folder.chmod(0o755)
    assert exc.value.filename == str(target) and ".old.txt." not in str(exc.value)
    assert target.read_text() == "old\n"


def test_a_write_error_names_the_output(tmp_path: Path, monkeypatch) -> None:
    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    target = tmp_path / "out.txt"
    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OSError) as exc, atomic_write(target) as fh:  # was: no file name
        fh.write("1,1,0,0,10,10,1,-1,-1,-1\n")
    assert (exc.value.errno, exc.value.filename) == (errno.ENOSPC, str(target))
    assert not target.exists() and not list(tmp_path.iterdir())
    monkeypatch.undo()
    if os.path.exists("/dev/full"):  # written through
        with pytest.raises(OSError) as exc, atomic_write("/dev/full") as fh:
            fh.write("x" * 100_000)
        assert (exc.value.errno, exc.value.filename) == (errno.ENOSPC, "/dev/full")
        with pytest.raises(OSError) as exc, atomic_path("/dev/full") as tmp:
            tmp.write_bytes(b"x")
        assert (exc.value.errno, exc.value.filename) == (errno.ENOSPC, "/dev/full")
        from pftrack.io.atomic import staged_outputs

        with pytest.raises(OSError) as exc, staged_outputs() as stage:  # was: no file name
            stage("/dev/full").write_bytes(b"x")
        assert (exc.value.errno, exc.value.filename) == (errno.ENOSPC, "/dev/full")


def test_a_side_file_is_removed_when_its_block_ends(tmp_path: Path) -> None:
    """A run's lines as they come, beside its output; the output itself is not touched."""
    from pftrack.io.atomic import side_file

    out = tmp_path / "t.txt"
    out.write_text("earlier\n")
    with side_file(out) as side:
        side.write_lines(["1,1", "1,2"])
        assert side.path.parent == tmp_path and side.path.name.startswith(".t.txt.")
        assert side.path.read_text() == "1,1\n1,2\n"  # flushed: readable while the run goes on
        assert out.read_text() == "earlier\n"
    assert side.kept is None and side.lines == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.txt"]
    with pytest.raises(KeyboardInterrupt), side_file(out):  # no line: nothing to keep
        raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.txt"]


def test_a_side_file_with_lines_is_kept_under_a_new_name_when_its_block_raises(
    tmp_path: Path,
) -> None:
    from pftrack.io.atomic import side_file

    out = tmp_path / "t.txt"
    out.write_text("earlier\n")
    out.chmod(0o600)
    kept = []
    for k in range(3):
        with pytest.raises(KeyboardInterrupt), side_file(out) as side:
            side.write_lines([f"run {k}"])
            raise KeyboardInterrupt
        kept.append(side.kept)
    names = ["t.partial.txt", "t.partial-2.txt", "t.partial-3.txt"]  # never one replaced
    assert kept == [tmp_path / n for n in names]
    assert [(tmp_path / n).read_text() for n in names] == ["run 0\n", "run 1\n", "run 2\n"]
    assert all(stat.S_IMODE((tmp_path / n).stat().st_mode) == 0o600 for n in names)
    assert out.read_text() == "earlier\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*names, "t.txt"])


def test_a_side_file_keeps_its_hidden_name_when_every_name_is_taken(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from pftrack.io import atomic

    monkeypatch.setattr(atomic, "PARTIAL_NAMES", 1)
    (tmp_path / "t.partial.txt").write_text("a user's file\n")
    with pytest.raises(RuntimeError), atomic.side_file(tmp_path / "t.txt") as side:
        side.write_lines(["row"])
        raise RuntimeError
    assert side.kept is not None and side.kept.name.startswith(".t.txt.")
    assert side.kept.read_text() == "row\n"
    assert (tmp_path / "t.partial.txt").read_text() == "a user's file\n"


@pytest.mark.parametrize("writer", ["atomic_write", "atomic_path", "side_file", "stage"])
def test_a_folder_that_is_a_file_is_named_so(writer: str, tmp_path: Path) -> None:
    """Was: ``output folder does not exist: notes.txt``; it exists, as a file."""
    from pftrack.io import atomic

    notes = tmp_path / "notes.txt"
    notes.write_text("x")
    target = notes / "sub" / "x.txt"

    def write(path: Path) -> None:
        if writer == "stage":
            with atomic.staged_outputs() as stage:
                stage(path)
        else:
            with getattr(atomic, writer)(path):
                pass

    with pytest.raises(
        NotADirectoryError, match=rf"^output {target}: {notes} is a file, not a folder$"
    ):
        write(target)
    missing = tmp_path / "no" / "x.txt"
    with pytest.raises(
        FileNotFoundError, match=rf"^output folder does not exist: {tmp_path / 'no'}$"
    ):
        write(missing)
    assert notes.read_text() == "x" and sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize("name", ["b" * 251 + ".txt", "b" + "é" * 125 + ".txt"])  # 255 bytes
def test_a_longest_valid_name_is_written(tmp_path: Path, name: str) -> None:
    """A user trial: names of 240-255 bytes, which ``touch`` makes, were refused ("File name
    too long"): the temporary name beside them was 14 bytes longer."""
    from pftrack.cli import main
    from pftrack.io.atomic import staged_outputs

    assert len(os.fsencode(name)) == 255
    for writer in (atomic_write, atomic_path):
        with writer(tmp_path / name) as out:
            if isinstance(out, Path):
                out.write_text("x\n")
            else:
                out.write("x\n")
        assert (tmp_path / name).read_text() == "x\n"
    with staged_outputs() as stage:
        stage(tmp_path / name).write_text("1,1,10,10,5,5,1,-1,-1,-1\n")  # tracks: recover's below
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]
    rows = tmp_path / "t.txt"
    write_mot(rows, [[1, 1, 10, 10, 5, 5, 1, -1, -1, -1], [3, 1, 14, 10, 5, 5, 1, -1, -1, -1]])
    assert main(["-q", "recover", str(rows), "--out", str(tmp_path / name)]) == 0


def test_a_writers_error_on_a_staged_file_names_the_output(tmp_path: Path) -> None:
    """A user trial on a full disk: ``No space left on device: full/.o.2833ba0ccefe.txt``, a
    name the user never gave."""
    from pftrack.io.atomic import staged_outputs

    target = tmp_path / "o.txt"
    with pytest.raises(OSError, match=r"No space left on device: '.*/o\.txt'$") as exc:
        with staged_outputs() as stage:
            tmp = stage(target)
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp))
    assert exc.value.errno == errno.ENOSPC
    assert list(tmp_path.iterdir()) == []


@pytest.fixture
def lost_ctrl_c() -> Iterator[None]:
    """The flag the ``pftrack`` console script's SIGINT handler sets, as if its interrupt had
    then been dropped by code in C (:mod:`pftrack._interrupt`); cleared after the test."""
    from pftrack import _interrupt

    _interrupt.remember()
    try:
        yield
    finally:
        _interrupt.clear()


@pytest.mark.parametrize("writer", ["atomic_write", "atomic_path", "staged_outputs"])
@pytest.mark.parametrize("existing", [True, False])
def test_after_a_lost_ctrl_c_no_writer_puts_its_output_in_place(
    tmp_path: Path, lost_ctrl_c: None, writer: str, existing: bool
) -> None:
    """Was: only ``recover`` and ``smooth`` checked the flag, before their one write; every
    other command's outputs were put in place after a Ctrl-C that code in C had dropped."""
    target = tmp_path / "out.txt"
    if existing:
        target.write_text("old\n")
    with pytest.raises(KeyboardInterrupt):
        _write_through(writer, target, "new\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == (["out.txt"] if existing else [])
    if existing:
        assert target.read_text() == "old\n"


@pytest.mark.parametrize("writer", ["atomic_write", "atomic_path", "staged_outputs"])
def test_after_a_lost_ctrl_c_nothing_is_written_into_a_pipe(
    tmp_path: Path, lost_ctrl_c: None, writer: str
) -> None:
    """A written-through output (a FIFO, ``/dev/stdout``) is refused before it is opened."""
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # the writer's open does not wait
    try:
        with pytest.raises(KeyboardInterrupt):
            _write_through(writer, fifo, "new\n")
        assert os.read(reader, 100) == b""  # nothing was written into the pipe
    finally:
        os.close(reader)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo"]


@pytest.mark.parametrize("writer", ["atomic_write", "atomic_path", "staged_outputs"])
def test_written_anyway_lets_an_interrupted_run_write_its_record(
    tmp_path: Path, lost_ctrl_c: None, writer: str
) -> None:
    """What a run writes because it was interrupted (a batch's summary.json) goes through."""
    from pftrack import _interrupt

    with _interrupt.written_anyway():
        _write_through(writer, tmp_path / "summary.json", "{}\n")
    assert (tmp_path / "summary.json").read_text() == "{}\n"
    assert _interrupt.interrupted()  # kept: the next write is refused again
    with pytest.raises(KeyboardInterrupt):
        _write_through(writer, tmp_path / "summary.json", "[]\n")
    assert (tmp_path / "summary.json").read_text() == "{}\n"


def test_a_ctrl_c_outside_the_console_script_is_not_remembered(tmp_path: Path) -> None:
    """Library use does not change: Python's own handler raises, and sets no flag, so a
    program that catches a Ctrl-C and goes on writes as before."""
    import signal

    from pftrack import _interrupt

    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with pytest.raises(KeyboardInterrupt):
        signal.raise_signal(signal.SIGINT)
    assert not _interrupt.interrupted()
    write_mot(tmp_path / "t.txt", [[1, 1, 0, 0, 10, 10]])
    assert (tmp_path / "t.txt").exists()


def test_a_tracks_file_does_not_replace_a_file_that_is_not_text(tmp_path: Path) -> None:
    """``check_output(tracks=True)`` refuses an existing binary file, under any name."""
    from pftrack.io.atomic import check_output

    video = tmp_path / "annotated.mp4"
    video.write_bytes(b"\x00\x00\x00\x18ftypisom" + bytes(range(256)))
    link = tmp_path / "tracks.txt"
    link.symlink_to(video)  # refused where it leads
    for out in (video, link):
        with pytest.raises(ValueError, match="is an existing file that is not text"):
            check_output(out, what="--out", tracks=True)
    check_output(video, what="--render")  # not a tracks file: replaced, as before
    text = tmp_path / "old.mp4"
    text.write_text("1,1,10,20,30,40,1,-1,-1,-1\n")  # text: replaced, whatever its name
    check_output(text, what="--out", tracks=True)
    check_output(tmp_path / "new.png", what="--out", tracks=True)  # none there yet
