"""A MOT file whose read fails part-way is named in the error, not left out.

A user's trial at stop 73: ``pftrack track --detections /proc/self/mem`` (a regular file
that no read can get through, as a failing disk or a network file system's file) said
``pftrack track: error: [Errno 5] Input/output error``, naming no file: which of the inputs?
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot
from pftrack.synthetic import make_scene

MEM = Path("/proc/self/mem")
linux = pytest.mark.skipif(
    not sys.platform.startswith("linux") or not MEM.is_file(), reason="needs /proc/self/mem"
)


@linux
def test_a_read_that_fails_names_the_file() -> None:
    with pytest.raises(OSError) as err:
        read_mot(MEM, what="detection file")
    assert err.value.filename == str(MEM) and err.value.errno is not None


@linux
@pytest.mark.parametrize(
    "argv",
    [
        ["recover", str(MEM)],
        ["smooth", str(MEM)],
        ["eval", "--gt", str(MEM), "--res", "RES"],
        ["track", "VIDEO", "--detections", str(MEM)],
    ],
)
def test_the_commands_say_it_on_one_line(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    res = tmp_path / "res.txt"
    res.write_text("1,1,10,10,5,5,1,-1,-1,-1\n")
    if "VIDEO" in argv:
        video = make_scene(n_frames=5, width=96, height=64, n_walkers=1, rng=0).write_video(
            tmp_path / "v.avi"
        )
        argv = [str(video) if a == "VIDEO" else a for a in argv]
    argv = [str(res) if a == "RES" else a for a in argv]
    if argv[0] != "eval":
        argv += ["--out", str(tmp_path / "o.txt")]
    assert main(["-q", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith(f": error: Input/output error: {MEM}"), err
    assert not (tmp_path / "o.txt").exists()


def test_the_columns_warning_still_names_the_callers_line(tmp_path: Path) -> None:
    path = tmp_path / "wide.txt"
    path.write_text("1,1,10,10,5,5,1,-1,-1,-1,7,8\n")
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        read_mot(path, warn_extra=True)
    assert [w.filename for w in said] == [__file__]
    assert "has lines of 12 columns" in str(said[0].message)
