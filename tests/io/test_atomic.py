"""Atomic outputs: all or nothing, and created with the user's umask."""

from __future__ import annotations

import os
import stat
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
