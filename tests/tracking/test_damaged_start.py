"""A video whose first frames do not decode: its reader's one warning, not three.

The reader puts a black frame in place of each (:class:`pftrack.io.video.FrameSource`, said
once). A user trial of the command on such a file (TUD-Campus re-encoded, its first key frame
damaged) printed two more warnings about the stand-ins, with advice wrong for them: frame 1
"blank ... (placeholder frames? give the real ones)" and "the frames from 1 on are dark
(... lights switched off, a fade to black, a covered lens?)". A run now keeps those two
quiet when the stand-ins explain them, and says them as before otherwise: the run marks the
stand-ins (`pftrack._stand_in`) and the checks skip them (was: the two warnings filtered by
their wording for the run's length).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pftrack import Tracker
from pftrack._stand_in import standing_in
from pftrack.cli import main
from pftrack.detection.blocking import BLOCK_FRAMES
from pftrack.detection.paper import DARK_FRAMES
from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from pftrack.tracking.run import track_frames, track_path
from tests.detection.test_blocking import resaved
from tests.io.encode import encode

LEAD = 10  # frames up to the second key frame: as many as DARK_FRAMES
assert LEAD >= DARK_FRAMES


def _damaged_start(tmp_path: Path) -> Path:
    """An H.264 walk whose first key frame is overwritten: frames 1-10 do not decode."""
    scene = make_scene(n_frames=40, width=160, height=120, rng=0)
    path = tmp_path / "walk.mp4"
    encode(path, scene.frames, options={"g": str(LEAD), "bf": "0"})
    data = bytearray(path.read_bytes())
    at = data.index(b"mdat") + 4
    data[at : at + 400] = np.random.default_rng(1).bytes(400)
    damaged = tmp_path / "damaged.mp4"
    damaged.write_bytes(bytes(data))
    return damaged


def _said(fn: Callable[[], object]) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fn()
    return [str(w.message) for w in caught]


@pytest.mark.parametrize("threads", [True, False])
@pytest.mark.parametrize("given", [False, True])
def test_stand_ins_are_said_once_by_the_reader(tmp_path: Path, threads: bool, given: bool) -> None:
    damaged = _damaged_start(tmp_path)
    det = None
    if given:
        det = tmp_path / "det.txt"
        det.write_text("".join(f"{f},-1,40,30,20,50,0.95,-1,-1,-1\n" for f in range(11, 41)))
    filters = list(warnings.filters)
    said = _said(lambda: track_path(damaged, detections=det, threads=threads))
    lead = [m for m in said if "could not be decoded" in m]
    assert len(lead) == 1 and "damaged.mp4: frames 1-10 could not be decoded (a damaged" in lead[0]
    assert not [m for m in said if "is blank" in m or "are dark" in m], said
    assert warnings.filters == filters  # the run's quiet ends with it


def test_the_command_prints_one_warning_for_the_stand_ins(tmp_path: Path, capsys) -> None:
    damaged = _damaged_start(tmp_path)
    assert main(["track", str(damaged), "--out", str(tmp_path / "t.txt")]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "frames 1-10 could not be decoded (a damaged start?)" in err[0], err


def test_the_source_counts_its_stand_ins(tmp_path: Path) -> None:
    source = FrameSource(_damaged_start(tmp_path))
    assert source.lead_black == 0  # not read yet
    with pytest.warns(UserWarning, match="a damaged start"):
        frames = list(source)
    assert source.lead_black == LEAD
    assert not any(f.any() for f in frames[:LEAD]) and frames[LEAD].any()


def test_black_frames_of_the_footage_itself_are_still_said(tmp_path: Path) -> None:
    """Frames black in the file (not stand-ins) keep both warnings: nothing quiets them."""
    scene = make_scene(n_frames=30, width=160, height=120, rng=0)
    frames = [np.zeros_like(f) for f in scene.frames[:LEAD]] + list(scene.frames[LEAD:])
    path = tmp_path / "black.avi"
    scene.frames = frames
    scene.write_video(path)
    said = _said(lambda: track_path(path))
    assert any(m.startswith("frame 1 is blank") for m in said), said
    assert any(m.startswith("the frames from 1 on are dark") for m in said), said


def test_no_warning_is_filtered_while_the_stand_ins_are_tracked(tmp_path: Path) -> None:
    """The checks skip the stand-ins (pftrack._stand_in): the run adds no filter by wording
    (was: two regexes on the warnings' text, for the run's length)."""
    filters = list(warnings.filters)
    during: list[bool] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the reader's own warning: not the subject here
        filters = list(warnings.filters)
        track_path(
            _damaged_start(tmp_path),
            on_frame=lambda *_: during.append(warnings.filters == filters),
        )
    assert len(during) == 40 and all(during)


def test_blockiness_is_measured_on_the_frames_after_the_stand_ins() -> None:
    """Black stand-ins measure 1 (no blocks): 8 of them decided a blocky video's first frames
    were not blocky. They are skipped: the first 8 real frames decide."""
    scene = make_scene(n_frames=BLOCK_FRAMES, width=192, height=144, n_walkers=3, rng=0)
    blocky = [resaved(f, 10) for f in scene.frames]
    black = np.zeros_like(blocky[0])

    def said(mark: bool) -> list[str]:
        tracker = Tracker(particles=30)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for _ in range(LEAD):
                with standing_in(mark):
                    tracker.update(None, black)
            for frame in blocky:
                tracker.update(None, frame)
        return [str(w.message) for w in caught]

    marked = said(True)
    assert [m for m in marked if "heavily compressed" in m], marked
    assert not [m for m in marked if "is blank" in m or "are dark" in m], marked
    unmarked = said(False)  # black frames of the footage itself: measured, and said as such
    assert not [m for m in unmarked if "heavily compressed" in m], unmarked
    assert [m for m in unmarked if "is blank" in m] and [m for m in unmarked if "are dark" in m]


@pytest.mark.parametrize("threads", [True, False])
@pytest.mark.parametrize("through", ["track_frames", "track_path"])
def test_the_detectors_warnings_name_the_callers_line(
    tmp_path: Path, threads: bool, through: str
) -> None:
    """The detector's "dark" warning was given on the detection thread, naming
    pftrack/tracking/ahead.py's line (with threads=False: run.py's loop): it names the line
    that called track_frames or track_path now, as the tracker's own warnings do."""
    scene = make_scene(n_frames=30, width=160, height=120, rng=0)
    frames = [np.zeros_like(f) for f in scene.frames[:LEAD]] + list(scene.frames[LEAD:])
    path = tmp_path / "black.avi"
    scene.frames = frames
    scene.write_video(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if through == "track_frames":
            track_frames(frames, threads=threads)
        else:
            track_path(path, threads=threads)
    said = {str(w.message).split(" (")[0]: w.filename for w in caught}
    assert said["the frames from 1 on are dark"] == __file__, said
    assert said["frame 1 is blank"] == __file__, said
