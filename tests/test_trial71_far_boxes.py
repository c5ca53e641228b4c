"""``pftrack recover`` and ``smooth`` of another tracker's rows say when some boxes lie far off.

A user's trial at stop 71: a MOTChallenge file of 183 rows of a 480x360 scene with 5 rows at
x = 1e7 (a tracker's diverged boxes) passed every check (values up to ±1e9 px); ``smooth``
carried them along their tracks, rows given at x = -50 came out at x = 2e6, exit 0, no word.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot, write_mot
from pftrack.synthetic import make_scene


def tracks(far: int = 0) -> np.ndarray:
    """A synthetic scene's truth with a fifth of its rows dropped; `far` rows moved to 1e7."""
    t = make_scene(n_frames=30, rng=0).truth
    t = t[np.random.default_rng(1).random(len(t)) > 0.2]
    t[4 : 4 + far, 2] = 1e7
    return t


@pytest.mark.filterwarnings("always::UserWarning")  # said as the command says it, not raised
@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_a_diverged_box_is_said_once_and_the_file_still_written(tmp_path, capsys, command):
    src, out = tmp_path / "bytetrack.txt", tmp_path / "out.txt"
    rows = tracks(far=3)
    write_mot(src, rows)
    assert main(["-q", command, str(src), "--out", str(out)]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line]
    assert len(err) == 1
    r = rows[4]
    assert err[0].startswith(
        f"pftrack {command}: warning: {src}: 3 rows with a box 100 times the others' spread or "
        f"more from them (the first: frame {r[0]:.0f}, id {r[1]:.0f}, left 1e+07, top {r[3]:g}, "
    )
    assert err[0].endswith("carry them along their tracks: mend or drop them first")
    assert len(read_mot(out))  # said, not refused


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_plausible_boxes_say_nothing(tmp_path, capsys, command):
    src = tmp_path / "t.txt"
    rows = tracks()
    rows[:5, 2] = -50.0  # partly outside the frame: a box may be
    write_mot(src, rows)
    assert main(["-q", command, str(src), "--out", str(tmp_path / "o.txt")]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.filterwarnings("always::UserWarning")
def test_a_folder_of_files_says_it_as_that_files_warning(tmp_path, capsys):
    folder, out = tmp_path / "res", tmp_path / "filled"
    folder.mkdir()
    write_mot(folder / "a.txt", tracks(far=1))
    write_mot(folder / "b.txt", tracks())
    assert main(["-q", "recover", str(folder), "--out", str(out), "--workers", "0"]) == 0
    said = {
        p.stem: json.loads(p.read_text()).get("warnings", []) for p in sorted(out.glob("?.json"))
    }
    assert [w.split(": ", 1)[1][:40] for w in said["a"]] == [
        "1 row with a box 100 times the others' s"
    ]
    assert said["b"] == []
    capsys.readouterr()


def test_the_rule() -> None:
    from pftrack.io.mot import far_boxes_note  # here: the tests above run on older code too

    rows = tracks()
    assert far_boxes_note(rows) is None
    assert far_boxes_note(rows[:3]) is None  # too few to judge
    n = len(rows) // 4 - 1  # a quarter of the rows, less one: the quartiles still hold
    moved = rows.copy()
    moved[:n, 3] = -5e6
    note = far_boxes_note(moved)
    assert note is not None and note.startswith(f"{n} rows with a box ")
    # a box 99 times the spread away is not said, 101 times is
    centre = rows[:, 2] + rows[:, 4] / 2
    q1, mid, q3 = np.percentile(centre, [25, 50, 75])
    spread = max(q3 - q1, np.median(rows[:, 4]), 1.0)
    for times, said in ((99, False), (101, True)):
        one = rows.copy()
        one[0, 2] = mid + times * spread - one[0, 4] / 2
        assert (far_boxes_note(one) is not None) is said


DATA = Path(os.environ.get("PFTRACK_DATA", Path(__file__).parents[1] / ".." / "shared" / "data"))


@pytest.mark.skipif(not DATA.is_dir(), reason="no shared data")
def test_the_datas_files_say_nothing() -> None:
    from pftrack.io.mot import far_boxes_note

    files = sorted(DATA.glob("**/gt.txt")) + sorted(DATA.glob("**/det.txt"))
    assert files
    for path in files:
        assert far_boxes_note(read_mot(path)) is None, path
