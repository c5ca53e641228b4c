"""A detection file numbered from 0 without a row on frame 0 is said, not taken in silence.

A user's trial at stop 73 (stop 72's leftover): MOTChallenge frames count from 1, KITTI's
labels, a decoder's index and Python's ``enumerate`` from 0. A file numbered from 0 with a row
on frame 0 is refused with the mend; one whose first detection is on frame 3 was read as
numbered from 1, exit 0 and no word, every box drawn on the frame before its own. What tells
it: a detector that finds something on nearly every frame ends one frame short of the video.
Both bases are tried on one synthetic scene: the file numbered from 1 says nothing, the file
numbered from 0 says it once, and the mend it prints gives the tracks of the file from 1.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import zero_based_note
from pftrack.synthetic import make_scene

FRAMES = 40
SAID = "numbered from 0 (KITTI, a decoder's index, enumerate)?"


@pytest.fixture(scope="module")
def scene(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray]:
    """A 40-frame video and its truth's boxes as detections (frame, -1, box, 0.95), from 1."""
    folder = tmp_path_factory.mktemp("scene")
    s = make_scene(n_frames=FRAMES, rng=1)
    video = s.write_video(folder / "video.avi")
    dets = s.truth.copy()
    dets[:, 1], dets[:, 6] = -1, 0.95
    assert set(dets[:, 0].astype(int)) == set(range(1, FRAMES + 1))  # a box on every frame
    return video, dets


def det_file(path: Path, rows: np.ndarray) -> Path:
    np.savetxt(path, rows, fmt="%g", delimiter=",")
    return path


def track(video: Path, dets: Path, out: Path, capsys: pytest.CaptureFixture[str]) -> list[str]:
    """``pftrack track --detections``'s warnings (exit 0 asserted)."""
    assert main(["-q", "track", str(video), "--detections", str(dets), "--out", str(out)]) == 0
    return [line for line in capsys.readouterr().err.splitlines() if "warning" in line]


def test_the_note_judges_the_last_frame_and_the_rows_density() -> None:
    note = zero_based_note(range(3, 40), 40, "det.txt")
    assert note is not None and note.startswith(
        f"det.txt: detections on 37 of frames 3-39, and none on the video's last frame, 40: {SAID}"
    )
    assert "add 1 to every frame (awk -F, -v OFS=, '{$1+=1}1' det.txt > det1.txt)" in note
    assert zero_based_note(range(1, 41), 40, "d") is None  # reaches the last frame
    assert zero_based_note(range(3, 41), 40, "d") is None  # from 1, first rows on frame 3
    assert zero_based_note(range(3, 39), 40, "d") is None  # ends two frames short
    assert zero_based_note(range(1, 40, 2), 40, "d") is None  # a row every other frame
    assert zero_based_note(range(3, 40), 0, "d") is None  # a count not known (a camera)
    assert zero_based_note(range(31, 40), 40, "d") is None  # 9 frames: too few to judge
    assert zero_based_note([39, *range(30, 40)], 40, "d") is not None  # repeats counted once


def test_a_file_numbered_from_1_says_nothing(
    scene: tuple[Path, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video, dets = scene
    assert track(video, det_file(tmp_path / "d.txt", dets), tmp_path / "t.txt", capsys) == []
    late = dets[dets[:, 0] >= 3]  # its first detections on frame 3: still from 1
    assert track(video, det_file(tmp_path / "l.txt", late), tmp_path / "u.txt", capsys) == []


def test_a_file_numbered_from_0_without_frame_0_is_said_and_the_mend_works(
    scene: tuple[Path, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video, dets = scene
    zero = dets.copy()
    zero[:, 0] -= 1
    det_file(tmp_path / "with0.txt", zero)  # with its frame-0 rows: refused, as before
    code = main(["-q", "track", str(video), "--detections", str(tmp_path / "with0.txt"),
                 "--out", str(tmp_path / "x.txt")])  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "numbered from 0? add 1 to every frame" in err[0]
    cut = det_file(tmp_path / "det0.txt", zero[zero[:, 0] >= 3])  # first detection on frame 3
    said = track(video, cut, tmp_path / "t0.txt", capsys)
    assert len(said) == 1, said
    assert said[0].startswith(
        f"pftrack track: warning: {cut}: detections on 37 of frames 3-39, and none on the "
        f"video's last frame, 40: {SAID}"
    )
    # the mend as printed (awk, where there is one) gives the rows of the file numbered from 1
    mended = tmp_path / "det1.txt"
    awk = said[0].split("(awk ")[1].split(" > det1.txt")[0]
    if Path("/usr/bin/awk").exists() or Path("/bin/awk").exists():
        script = awk.split(" -v OFS=, ")[1].split(f" {cut}")[0].strip("'")
        text = subprocess.run(
            ["awk", "-F,", "-v", "OFS=,", script, str(cut)], check=True, capture_output=True,
            text=True,
        ).stdout  # fmt: skip
        mended.write_text(text)
    else:  # pragma: no cover - the same sum, without awk
        rows = np.loadtxt(cut, delimiter=",")
        rows[:, 0] += 1
        det_file(mended, rows)
    assert track(video, mended, tmp_path / "t1.txt", capsys) == []
    det_file(tmp_path / "from4.txt", dets[dets[:, 0] >= 4])
    assert track(video, tmp_path / "from4.txt", tmp_path / "t4.txt", capsys) == []
    assert (tmp_path / "t1.txt").read_bytes() == (tmp_path / "t4.txt").read_bytes()
    # and the unmended run was not those tracks: every box a frame early
    assert (tmp_path / "t0.txt").read_bytes() != (tmp_path / "t4.txt").read_bytes()


def test_batch_says_it_as_the_sequences_warning(
    scene: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    video, dets = scene
    seq = tmp_path / "in" / "seq0"
    (seq / "det").mkdir(parents=True)
    (seq / "video.avi").write_bytes(video.read_bytes())
    (seq / "seqinfo.ini").write_text(
        f"[Sequence]\nname=seq0\nseqLength={FRAMES}\nimWidth=480\nimHeight=360\nframeRate=10\n"
    )
    zero = dets.copy()
    zero[:, 0] -= 1
    det_file(seq / "det" / "det.txt", zero[zero[:, 0] >= 3])
    run = subprocess.run(
        [sys.executable, "-m", "pftrack", "-q", "batch", str(tmp_path / "in"), "--out",
         str(tmp_path / "out"), "--workers", "0", "--detections", "auto"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    said = [line for line in run.stderr.splitlines() if SAID in line]
    assert len(said) == 1 and said[0].startswith("seq0: warning: "), run.stderr
    assert SAID in (tmp_path / "out" / "seq0.json").read_text()


def test_track_path_says_it_once_as_the_command_does(
    scene: tuple[Path, np.ndarray], tmp_path: Path
) -> None:
    from pftrack.tracking.run import track_path

    video, dets = scene
    zero = dets.copy()
    zero[:, 0] -= 1
    cut = det_file(tmp_path / "det0.txt", zero[zero[:, 0] >= 3])
    with pytest.warns(UserWarning) as said:
        track_path(video, detections=cut, show_progress=False)
    notes = [str(w.message) for w in said if SAID in str(w.message)]
    assert len(notes) == 1 and notes[0].startswith(f"{cut}: detections on 37 of frames 3-39")


def test_render_says_it_of_tracks_numbered_from_0(
    scene: tuple[Path, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video, dets = scene
    tracks = make_scene(n_frames=FRAMES, rng=1).truth  # ids, frames 1-40
    for name, rows, said in (("t1.txt", tracks, 0), ("t0.txt", tracks[tracks[:, 0] < FRAMES], 1)):
        path = det_file(tmp_path / name, rows)
        argv = ["-q", "render", str(video), str(path), "--out", str(tmp_path / f"{name}.mp4")]
        assert main(argv) == 0
        notes = [line for line in capsys.readouterr().err.splitlines() if SAID in line]
        assert len(notes) == said, notes
    assert notes[0].startswith(
        f"pftrack render: warning: {path}: rows on 39 of frames 1-39, and none on the video's "
        "last frame, 40: "
    )
    assert notes[0].endswith(
        f"'{{$1+=1}}1' {path} > tracks1.txt); if the file counts from 1, nothing is wrong"
    )
