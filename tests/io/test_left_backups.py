"""A backup a killed run left (``.NAME.<hex>.old``) is said by the next write into its folder.

Only a ``kill -9`` during :func:`~pftrack.io.atomic.staged_outputs`' renames leaves one; without
hard links it is the only copy of the user's earlier file. Was: kept without a word, so the user
never learnt where the old file went. Now the first write of a run into that folder warns of
each, in one line naming it and its output, and leaves it as it is.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import pytest

from pftrack.cli import main
from pftrack.io.atomic import atomic_path, atomic_write, staged_outputs

STALE = ".t.txt.0123456789ab.old"


def _said(record: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in record]


@pytest.mark.parametrize("kind", ["earlier", "only copy", "same file"])
def test_staged_outputs_says_each_left_backup_and_keeps_it(tmp_path: Path, kind: str) -> None:
    out, stale = tmp_path / "t.txt", tmp_path / STALE
    if kind == "same file":  # killed after the backups were made, before any rename
        out.write_bytes(b"now")
        os.link(out, stale)
    else:  # killed after t.txt was renamed: its earlier contents are the backup's alone
        stale.write_bytes(b"earlier")
        if kind == "earlier":
            out.write_bytes(b"now")
    with warnings.catch_warnings(record=True) as record, staged_outputs() as stage:
        warnings.simplefilter("always")
        stage(tmp_path / "v.txt").write_bytes(b"new")
    said = f"{stale} was left by a pftrack run killed while it replaced t.txt, and "
    said += {
        "earlier": "holds its earlier contents: delete it, or move it back over t.txt to have "
        "them again",
        "only copy": f"is that file's only copy: move it back (mv {stale} {out})",
        "same file": "is another name for t.txt as it is: delete it, nothing is lost",
    }[kind]
    assert _said(record) == [said]
    assert stale.read_bytes() == (b"now" if kind == "same file" else b"earlier")


def test_each_backup_once_per_folder(tmp_path: Path) -> None:
    """Two backups: two lines; the process's later writes into that folder say nothing more."""
    (tmp_path / STALE).write_bytes(b"earlier t")
    (tmp_path / ".v.mp4.00000000000f.old").write_bytes(b"earlier v")
    (tmp_path / ".t.txt.0123.old").write_bytes(b"not a backup's name: 4 digits")
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        with atomic_write(tmp_path / "a.txt") as fh:
            fh.write("a")
        with atomic_path(tmp_path / "b.bin") as tmp:
            tmp.write_bytes(b"b")
        with staged_outputs() as stage:
            stage(tmp_path / "c.txt").write_bytes(b"c")
    assert [m.split(" was left by ")[0] for m in _said(record)] == [
        str(tmp_path / STALE),
        str(tmp_path / ".v.mp4.00000000000f.old"),
    ]
    assert len(list(tmp_path.iterdir())) == 6


@pytest.mark.parametrize("writer", ["atomic_write", "atomic_path"])
def test_one_output_writers_say_it_too(tmp_path: Path, writer: str) -> None:
    (tmp_path / STALE).write_bytes(b"earlier")
    with pytest.warns(UserWarning, match=r"\.t\.txt\.0123456789ab\.old was left by") as record:
        if writer == "atomic_write":
            with atomic_write(tmp_path / "t.txt") as fh:
                fh.write("new")
        else:
            with atomic_path(tmp_path / "t.txt") as tmp:
                tmp.write_text("new")
    assert len(record) == 1 and (tmp_path / STALE).read_bytes() == b"earlier"


@pytest.mark.filterwarnings("always::UserWarning")  # as a user's Python shows them
def test_the_command_says_it_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``pftrack smooth`` into a folder holding a left backup: one warning line, exit 0."""
    tracks, out = tmp_path / "in.txt", tmp_path / "out" / "t.txt"
    tracks.write_text("".join(f"{f},1,{10 + f},20,30,60,1,-1,-1,-1\n" for f in range(1, 9)))
    out.parent.mkdir()
    (out.parent / STALE).write_bytes(b"earlier")
    assert main(["-q", "smooth", str(tracks), "--out", str(out)]) == 0
    err = capsys.readouterr().err.splitlines()
    said = [line for line in err if "was left by" in line]
    assert said == [
        f"pftrack smooth: warning: {out.parent / STALE} was left by a pftrack run killed while "
        f"it replaced t.txt, and is that file's only copy: move it back (mv {out.parent / STALE} "
        f"{out})"
    ]
    assert (out.parent / STALE).read_bytes() == b"earlier" and out.is_file()
