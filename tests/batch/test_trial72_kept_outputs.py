"""A batch task that fails says which of its outputs in --out an earlier run left there.

A user's trial at stop 72: ``pftrack batch seqs --out res`` tracked ``imgs``; one of its
images was then replaced by one of another size, and the re-run failed ``imgs`` (exit 1,
its error said) but left ``res/imgs.txt`` and ``res/imgs.json`` of the old images beside the
other sequences' new files, unsaid: ``pftrack recover res`` or ``pftrack eval`` of the folder
read them as this run's tracks. Nothing is removed: outputs are replaced whole or not at all.
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2

from pftrack.cli import main
from pftrack.synthetic import make_scene

NOTE = (
    "imgs: warning: imgs.txt and imgs.json in {out} are an earlier run's, left as they were: "
    "not this run's (it failed), nor, if its inputs or settings changed since, theirs; move "
    "them away before reading the folder's results (pftrack recover, eval)"
)


def folders(root: Path) -> Path:
    """``root/seqs`` with two 12-frame image folders, ``imgs`` and ``other``."""
    for name, seed in (("imgs", 0), ("other", 1)):
        folder = root / "seqs" / name
        folder.mkdir(parents=True)
        for k, frame in enumerate(make_scene(n_frames=12, rng=seed).frames, start=1):
            assert cv2.imwrite(str(folder / f"{k:04d}.png"), frame)
    return root / "seqs"


def break_imgs(seqs: Path) -> None:
    """Image 6 of ``imgs`` at half the size of the others: its task fails when it reads it."""
    path = seqs / "imgs" / "0006.png"
    assert cv2.imwrite(str(path), cv2.resize(cv2.imread(str(path)), (240, 180)))


def batch(seqs: Path, out: Path, *more: str) -> int:
    return main(["-q", "batch", str(seqs), "--out", str(out), "--workers", "0", *more])


def entry(out: Path, name: str) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    return next(e for e in summary["sequences"] if e["name"] == name)


def test_a_failed_rerun_names_the_earlier_outputs_it_left(tmp_path: Path, capsys) -> None:
    seqs, out = folders(tmp_path), tmp_path / "res"
    assert batch(seqs, out) == 0
    before = {p.name: p.read_bytes() for p in out.glob("imgs.*")}
    assert sorted(before) == ["imgs.json", "imgs.txt"]
    capsys.readouterr()
    break_imgs(seqs)
    assert batch(seqs, out) == 1
    err = capsys.readouterr().err.splitlines()
    assert [line for line in err if "earlier run's" in line] == [NOTE.format(out=out)]
    assert (
        err.index(NOTE.format(out=out))
        == next(  # right after its error
            i for i, line in enumerate(err) if line.startswith("imgs: error: ")
        )
        + 1
    )
    assert entry(out, "imgs")["status"] == "failed"
    assert entry(out, "imgs")["kept"] == ["imgs.txt", "imgs.json"]
    assert "kept" not in entry(out, "other")  # skipped: complete, its own
    assert {p.name: p.read_bytes() for p in out.glob("imgs.*")} == before  # nothing removed


def test_force_says_it_too(tmp_path: Path, capsys) -> None:
    seqs, out = folders(tmp_path), tmp_path / "res"
    assert batch(seqs, out) == 0
    break_imgs(seqs)
    capsys.readouterr()
    assert batch(seqs, out, "--force") == 1
    assert NOTE.format(out=out) in capsys.readouterr().err.splitlines()
    assert entry(out, "imgs")["kept"] == ["imgs.txt", "imgs.json"]


def test_a_task_failing_with_no_earlier_outputs_says_nothing_of_them(
    tmp_path: Path, capsys
) -> None:
    seqs, out = folders(tmp_path), tmp_path / "res"
    break_imgs(seqs)
    assert batch(seqs, out) == 1
    assert "earlier run's" not in capsys.readouterr().err
    assert "kept" not in entry(out, "imgs")
    assert not list(out.glob("imgs.*"))


def test_the_note_for_one_file() -> None:
    from pftrack.batch.engine import kept_note

    assert kept_note(["a.txt"], Path("res")).startswith(
        "a.txt in res is an earlier run's, left as it was: not this run's (it failed)"
    )
    assert "move it away" in kept_note(["a.txt"], Path("res"))
    assert kept_note(["a.txt", "a.json", "a.mp4"], Path("r")).startswith(
        "a.txt, a.json and a.mp4 in r are an earlier run's"
    )
