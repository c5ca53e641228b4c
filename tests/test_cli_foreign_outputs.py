"""Every output option replaces only what pftrack wrote, an empty file or nothing; ``--force``.

Until stop 68 ``--plot``, ``--figure``, ``--json`` and ``--csv`` (and a tracks ``--out`` over
any text file: notes, a script) replaced any existing file that was not an input, exit 0: a
user's picture or JSON typed for the output was gone. Each kind now carries a mark
(:mod:`pftrack.io.marks`: a PNG's tEXt chunk, a JPEG's comment, a JSON's first key, the CSV's
header; a tracks file is MOTChallenge rows, anyone's), and one rule holds for all (docs/io.md,
"What an output may replace"): any other non-empty file is refused with exit 2 and one line,
unless ``--force``. Re-running a command into its own earlier output still replaces it.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.marks import (
    is_marked_csv,
    is_marked_image,
    is_marked_json,
    json_marked,
    mark_image,
)
from pftrack.io.mot import is_mot_text, read_mot
from pftrack.synthetic import make_scene
from tests.test_cli import _walkers

#: What a user had at the output's path: a picture, a JSON file, a CSV file, notes.
_PICTURE = cv2.imencode(".png", np.full((6, 8, 3), 7, np.uint8))[1].tobytes()
_JPEG = cv2.imencode(".jpg", np.full((6, 8, 3), 7, np.uint8))[1].tobytes()
_THEIRS = {
    ".png": _PICTURE,
    ".jpg": _JPEG,
    ".json": b'{"mine": 1}\n',
    ".csv": b"sequence,score\nA,1\n",
    ".txt": b"my notes: do not lose them\n",
}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("inputs")
    scene = make_scene(n_frames=8, rng=0)
    return {
        "video": scene.write_video(d / "v.avi"),
        "gt": scene.write_truth(d / "gt.txt"),
        "walkers": _walkers(d / "walkers.txt"),
    }


def _argv(case: str, inputs: dict[str, Path], out: Path, tmp_path: Path) -> list[str]:
    video, gt = str(inputs["video"]), str(inputs["gt"])
    spare = str(tmp_path / "spare.txt")
    return {
        "track --out": ["track", video, "--out", str(out), "--particles", "20"],
        "track --plot": ["track", video, "--out", spare, "--plot", str(out), "--particles", "20"],
        "render --plot": ["render", video, gt, "--out", str(tmp_path / "r.avi"), "--plot",
                          str(out)],
        "recover --out": ["recover", gt, "--out", str(out)],
        "smooth --out": ["smooth", gt, "--out", str(out)],
        "eval --json": ["eval", "--gt", gt, "--res", gt, "--json", str(out)],
        "eval --csv": ["eval", "--gt", gt, "--res", gt, "--csv", str(out)],
        "experiment --json": ["experiment", "gaps", "--gt", str(inputs["walkers"]),
                              "--image-size", "768x576", "--mask", "0,0,2,2", "--methods",
                              "linear", "--repeat", "1", "--json", str(out)],
        "experiment --figure": ["experiment", "gaps", "--gt", str(inputs["walkers"]),
                                "--image-size", "768x576", "--mask", "0,0,2,2", "--methods",
                                "linear", "--repeat", "1", "--figure", str(out)],
    }[case]  # fmt: skip


_CASES = {  # each output option, its file's extension, and the test of pftrack's mark
    "track --out": (".txt", is_mot_text),
    "track --plot": (".png", is_marked_image),
    "render --plot": (".jpg", is_marked_image),
    "recover --out": (".txt", is_mot_text),
    "smooth --out": (".txt", is_mot_text),
    "eval --json": (".json", is_marked_json),
    "eval --csv": (".csv", is_marked_csv),
    "experiment --json": (".json", is_marked_json),
    "experiment --figure": (".png", is_marked_image),
}


@pytest.mark.filterwarnings("ignore::UserWarning")  # an 8-frame scene's notes, not the subject
@pytest.mark.parametrize("case", list(_CASES))
def test_a_users_file_is_refused_pftracks_replaced_and_force_replaces(
    case: str, inputs: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    suffix, ours = _CASES[case]
    out = tmp_path / f"mine{suffix}"
    out.write_bytes(_THEIRS[suffix])
    command, option = case.rsplit(maxsplit=1)
    command += " gaps" if command == "experiment" else ""
    assert main(["-q", *_argv(case, inputs, out, tmp_path)]) == 2
    what = "holds no MOTChallenge rows" if option == "--out" else "pftrack did not write"
    assert capsys.readouterr().err == (
        f"pftrack {command}: error: {option} {out} is an existing file that {what} (a file of "
        "yours?), and would be replaced: move it, give another name, or pass --force\n"
    )
    assert out.read_bytes() == _THEIRS[suffix]  # was: replaced, exit status 0
    assert not ours(out)
    assert main(["-q", *_argv(case, inputs, out, tmp_path), "--force"]) == 0
    assert ours(out)
    for _ in range(2):  # its own output, and again: re-running into it replaces it
        assert main(["-q", *_argv(case, inputs, out, tmp_path)]) == 0, capsys.readouterr().err
        assert ours(out)
    out.write_bytes(b"")  # an empty file: nothing to lose
    assert main(["-q", *_argv(case, inputs, out, tmp_path)]) == 0
    assert ours(out)


def test_another_trackers_mot_file_is_replaced_as_motchallenge_tools_do(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """A tracks file has no room for a mark: any MOTChallenge rows are a tracker's output."""
    out = tmp_path / "theirs.txt"
    for text in (
        "1 1 10 10 5 5 1 -1 -1 -1\n",
        "# a comment\n\n2,3,1.5,2,3e1,4,0.9\n",
        "#\n",
        "\ufeff1,1,10,10,5,5,1,-1,-1,-1\r\n",
    ):  # a byte-order mark, as read_mot takes
        out.write_text(text, encoding="utf-8")
        assert is_mot_text(out)
        assert main(["-q", "recover", str(inputs["gt"]), "--out", str(out)]) == 0
        assert is_mot_text(out) and out.read_text(encoding="utf-8") != text
    for text in ("frame,id,x,y,w,h\n", "1,2,3,4,5\n", "1,2,3,4,5,six\n", "\0binary"):
        out.write_text(text)
        assert not is_mot_text(out), text


def test_mot_text_is_what_read_mot_reads_as_rows(tmp_path: Path) -> None:
    """The test of a tracks ``--out`` and ``read_mot`` agree (it had its own split and number
    pattern: a UTF-16 file ``read_mot`` reads was refused, full-width digits it refuses were
    taken, as was a row with an empty column)."""
    path = tmp_path / "rows.txt"
    path.write_text("1,1,10,10,5,5,1,-1,-1,-1\n", encoding="utf-16")
    assert is_mot_text(path) and read_mot(path).shape == (1, 10)
    for text in ("\uff11,1,10,10,5,5\n", "1,,10,10,5,5,1\n"):
        path.write_text(text, encoding="utf-8")
        assert not is_mot_text(path), text
        with pytest.raises(ValueError):
            read_mot(path)


@pytest.mark.parametrize("ext", [".png", ".jpg"])
def test_the_image_mark_keeps_the_pixels(ext: str) -> None:
    rng = np.random.default_rng(0)
    image = rng.integers(0, 256, (40, 60, 3), dtype=np.uint8)
    plain = cv2.imencode(ext, image)[1].tobytes()
    marked = mark_image(plain)
    assert marked != plain and len(marked) > len(plain)
    decode = lambda b: cv2.imdecode(np.frombuffer(b, np.uint8), cv2.IMREAD_COLOR)  # noqa: E731
    np.testing.assert_array_equal(decode(marked), decode(plain))
    assert mark_image(b"GIF89a") == b"GIF89a"  # another format: as it is


@pytest.mark.parametrize(
    ("name", "data", "test"),
    [
        ("p.png", mark_image(_PICTURE), is_marked_image),
        ("p.jpg", mark_image(_JPEG), is_marked_image),
        ("d.json", json.dumps(json_marked({"a": 1}, "eval"), indent=1).encode(), is_marked_json),
        ("s.csv", b"sequence,hota,det_a\nA,0.5,0.4\n", is_marked_csv),
    ],
)
def test_each_mark_is_told_from_its_absence(
    name: str, data: bytes, test: Callable[[Path], bool], tmp_path: Path
) -> None:
    path = tmp_path / name
    path.write_bytes(data)
    assert test(path)
    path.write_bytes(_THEIRS[path.suffix])
    assert not test(path)
    assert not test(tmp_path / "missing")
    assert not test(tmp_path)  # a folder: not readable as a file, not ours
