"""``--det-base``: a detection file's frame numbering, stated (a user's trial at stop 74).

Stop 73 left a file numbered from 0 only warned about (`zero_based_note`, when it is dense)
or refused (a row on frame 0), with an ``awk`` to rewrite it; a sparse one was read a frame
late without a word. MOTChallenge's det.txt, gt.txt and every tracker's MOT export count from
1 (the default, as before); a decoder's index, KITTI's frames and Python's ``enumerate`` count
from 0. ``--det-base 0`` (``pftrack track``, ``pftrack batch``; :class:`MotFile` in Python,
for ``load_detections``, ``track_path`` and ``TrackOptions(det_base=0)`` for ``track_many``)
reads such a file as it is: its tracks are those of the same file numbered from 1.
``--det-base 1`` states MOTChallenge's numbering and silences the note.
"""

from __future__ import annotations

import json
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import FRAME_BASES, MotFile, read_mot, zero_based_note
from tests import test_trial73_zero_based as zero_based

# the scene and the note's words of trial73's tests (a video and its truth as detections)
FRAMES, SAID, scene = zero_based.FRAMES, zero_based.SAID, zero_based.scene


def det_file(path: Path, rows: np.ndarray) -> Path:
    np.savetxt(path, rows, fmt="%g", delimiter=",")
    return path


def from_0(rows: np.ndarray) -> np.ndarray:
    zero = rows.copy()
    zero[:, 0] -= 1
    return zero


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    """Exit status and stderr's lines of ``pftrack ARGV`` (argparse's refusals exit)."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = int(exc.code or 0)
    return code, capsys.readouterr().err.strip().splitlines()


def test_read_mot_from_0_adds_1_to_every_frame_as_numpy_does(tmp_path: Path) -> None:
    rows = np.array([[0, -1, 10, 20, 30, 40, 0.9], [0, -1, 1, 2, 3, 4, 0.5],
                     [7, -1, 5.5, 6, 7, 8, 0.25]])  # fmt: skip
    plain = det_file(tmp_path / "d.txt", rows)
    commented = tmp_path / "c.txt"  # a comment line: the line-by-line reader, not the fast one
    commented.write_text("# frames from 0\n" + plain.read_text())
    want = np.loadtxt(plain, delimiter=",")
    want[:, 0] += 1
    for path in (plain, commented):
        for got in (read_mot(path, first_frame=0), read_mot(MotFile(path, first_frame=0))):
            np.testing.assert_array_equal(got[:, :7], want)
            np.testing.assert_array_equal(got[:, 7:], -1)
        with pytest.raises(ValueError, match="frame is 0, expected an integer in 1"):
            read_mot(path)  # from 1 (a plain path, MOTChallenge's): frame 0 refused
        np.testing.assert_array_equal(read_mot(MotFile(path, 1), first_frame=0)[:, 0], want[:, 0])
    minus = tmp_path / "m.txt"
    minus.write_text("-1,-1,1,2,3,4,0.5\n")
    with pytest.raises(ValueError, match=r"m.txt:1: frame is -1, expected an integer in 0\.\."):
        read_mot(minus, first_frame=0)


def test_motfile_is_a_path_with_its_numbering() -> None:
    m = MotFile("det0.txt", first_frame=0)
    assert str(m) == "det0.txt" and Path(m) == Path("det0.txt")
    assert repr(m) == "MotFile('det0.txt', first_frame=0)"
    assert pickle.loads(pickle.dumps(m)) == m != MotFile("det0.txt")
    assert MotFile(Path("a")).first_frame == 1 and FRAME_BASES == (0, 1)
    with pytest.raises(ValueError, match=r"^MotFile: first_frame is 2, expected 0 \(frames"):
        MotFile("a", 2)
    with pytest.raises(TypeError, match="^MotFile: first_frame must be 0 or 1, got bool"):
        MotFile("a", True)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="^MotFile: path must be a str or os.PathLike"):
        MotFile(None)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="^read_mot: first_frame is -1"):
        read_mot("x.txt", first_frame=-1)


def test_a_stated_numbering_silences_the_note() -> None:
    assert zero_based_note(range(3, 40), 40, "det.txt") is not None
    assert zero_based_note(range(3, 40), 40, MotFile("det.txt", 1)) is None
    assert zero_based_note(range(3, 40), 40, MotFile("det.txt", 0)) is None
    note = zero_based_note(range(3, 40), 40, "det.txt")
    assert note is not None and "read it with --det-base 0" in note
    assert note.endswith("nothing is wrong (--det-base 1 says so, and silences this)")
    rows = zero_based_note(range(3, 40), 40, "t.txt", what="rows")  # render's: no such option
    assert rows is not None and "--det-base" not in rows


def test_track_det_base_0_gives_the_tracks_of_the_file_from_1(
    scene: tuple[Path, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video, dets = scene
    one = det_file(tmp_path / "det1.txt", dets)
    zero = det_file(tmp_path / "det0.txt", from_0(dets))  # with rows on frame 0
    base = ["-q", "track", str(video), "--detections"]
    assert run([*base, str(one), "--out", str(tmp_path / "t1.txt")], capsys) == (0, [])
    # frame 0 without the option: refused, one line, the option named as the way out
    code, err = run([*base, str(zero), "--out", str(tmp_path / "x.txt")], capsys)
    assert code == 2 and len(err) == 1 and "--det-base 0" in err[0], err
    assert not (tmp_path / "x.txt").exists()
    out = tmp_path / "t0.txt"
    assert run([*base, str(zero), "--det-base", "0", "--out", str(out)], capsys) == (0, [])
    assert out.read_bytes() == (tmp_path / "t1.txt").read_bytes()
    # a sparse file from 0 (no row on frame 0, none past 30): nothing tells it, the option does
    sparse = from_0(dets[(dets[:, 0] >= 4) & (dets[:, 0] <= 30)])
    det_file(tmp_path / "s0.txt", sparse)
    det_file(tmp_path / "s1.txt", dets[(dets[:, 0] >= 4) & (dets[:, 0] <= 30)])
    for name, extra in (("s0.txt", ["--det-base", "0"]), ("s1.txt", [])):
        argv = [*base, str(tmp_path / name), *extra, "--out", str(tmp_path / f"t{name}")]
        assert run(argv, capsys) == (0, [])
    assert (tmp_path / "ts0.txt").read_bytes() == (tmp_path / "ts1.txt").read_bytes()


def test_track_det_base_1_states_the_numbering_and_says_nothing(
    scene: tuple[Path, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video, dets = scene
    cut = det_file(tmp_path / "d.txt", from_0(dets)[dets[:, 0] >= 4])  # dense, ends at 39
    base = ["-q", "track", str(video), "--detections", str(cut)]
    code, err = run([*base, "--out", str(tmp_path / "a.txt")], capsys)
    assert code == 0 and len(err) == 1 and SAID in err[0] and "--det-base 0" in err[0]
    assert run([*base, "--det-base", "1", "--out", str(tmp_path / "b.txt")], capsys) == (0, [])
    assert (tmp_path / "a.txt").read_bytes() == (tmp_path / "b.txt").read_bytes()


@pytest.mark.parametrize(
    ("extra", "said"),
    [
        (["--det-base", "2"], "argument --det-base: invalid choice: 2 (choose from 0, 1)"),
        (["--det-base", "x"], "argument --det-base: invalid int value: 'x'"),
        (["--det-base", "0"], "--det-base 0 says how --detections numbers its frames; the "
                              "built-in detector reads no file: drop it, or give --detections"),
    ],
)  # fmt: skip
def test_track_det_base_refusals(
    scene: tuple[Path, np.ndarray],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    extra: list[str],
    said: str,
) -> None:
    video, _ = scene
    code, err = run(["-q", "track", str(video), *extra, "--out", str(tmp_path / "t.txt")], capsys)
    assert code == 2 and len(err) == 1 and err[0].endswith(said), err


@pytest.mark.parametrize("command", ["track", "batch"])
def test_help_states_the_default(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--det-base {0,1}" in text
    assert "(default: 1, MOTChallenge's, with a warning for a file that looks numbered" in text


def test_the_cli_states_the_readers_bases() -> None:
    from pftrack.cli._options import DET_BASES

    assert DET_BASES == FRAME_BASES


def test_track_path_and_load_detections_take_a_motfile(
    scene: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    import pftrack
    from pftrack.tracking.run import track_path

    video, dets = scene
    one = det_file(tmp_path / "det1.txt", dets)
    zero = det_file(tmp_path / "det0.txt", from_0(dets))
    a, b = pftrack.load_detections(one), pftrack.load_detections(MotFile(zero, 0))
    assert a.keys() == b.keys() and all(np.array_equal(a[f], b[f]) for f in a)
    want = track_path(video, detections=one, show_progress=False).rows
    got = track_path(video, detections=MotFile(zero, 0), show_progress=False).rows
    np.testing.assert_array_equal(got, want)


def settings(sidecar: Path) -> dict[str, object]:
    """A batch sidecar's stored settings."""
    value: dict[str, object] = json.loads(sidecar.read_text())["settings"]
    return value


def _sequence(folder: Path, video: Path, dets: np.ndarray) -> Path:
    (folder / "det").mkdir(parents=True)
    (folder / "video.avi").write_bytes(video.read_bytes())
    (folder / "seqinfo.ini").write_text(
        f"[Sequence]\nname={folder.name}\nseqLength={FRAMES}\nimWidth=480\nimHeight=360\n"
    )
    det_file(folder / "det" / "det.txt", dets)
    return folder


def test_batch_det_base_0_reads_each_det_txt_from_0(
    scene: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    video, dets = scene
    _sequence(tmp_path / "zero" / "seqA", video, from_0(dets))
    _sequence(tmp_path / "one" / "seqA", video, dets)

    def batch(inputs: str, out: str, *extra: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "pftrack", "-q", "batch", str(tmp_path / inputs), "--out",
             str(tmp_path / out), "--workers", "0", "--detections", "auto", *extra],
            capture_output=True, text=True, check=False,
        )  # fmt: skip

    refused = batch("zero", "r0")
    assert refused.returncode == 1 and "--det-base 0" in refused.stderr, refused.stderr
    done = batch("zero", "r1", "--det-base", "0")
    assert done.returncode == 0, done.stderr
    assert batch("one", "r2").returncode == 0
    tracks = [(tmp_path / out / "seqA.txt").read_bytes() for out in ("r1", "r2")]
    assert tracks[0] == tracks[1]
    assert settings(tmp_path / "r1" / "seqA.json")["det_base"] == 0
    # without the option, the stored settings are those of the runs before it: still complete
    assert "det_base" not in settings(tmp_path / "r2" / "seqA.json")
    again = batch("one", "r2")
    assert again.returncode == 0 and "redone" not in again.stderr + again.stdout
    only = subprocess.run(
        [sys.executable, "-m", "pftrack", "batch", str(tmp_path / "one"), "--out",
         str(tmp_path / "r3"), "--det-base", "0"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert only.returncode == 2 and len(only.stderr.strip().splitlines()) == 1, only.stderr
    assert "--det-base 0 says how --detections numbers its frames" in only.stderr


def test_track_options_det_base() -> None:
    from pftrack.batch import TrackOptions

    assert "det_base" not in TrackOptions().settings()
    assert TrackOptions(detections="auto", det_base=0).settings()["det_base"] == 0
    with pytest.raises(ValueError, match="^TrackOptions: det_base is 0, but detections is None"):
        TrackOptions(det_base=0)
    with pytest.raises(ValueError, match="^TrackOptions: det_base is 5, expected 0"):
        TrackOptions(detections="auto", det_base=5)
    with pytest.raises(TypeError, match="^TrackOptions: det_base must be 0 or 1, got str"):
        TrackOptions(detections="auto", det_base="0")  # type: ignore[arg-type]
