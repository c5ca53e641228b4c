"""A Matroska file cut short is said, by its container's duration, not tracked to its cut silently.

A user trial of stop 65: an H.264 ``.mkv`` truncated to half its bytes was tracked over its
first 30 frames of 60 with exit 0 and no word. Matroska holds no frame count (OpenCV's is
FFmpeg's estimate, not held to: tests/io/test_estimated_count.py), but it holds the duration,
and the time stamp of the last frame decoded falls short of it whatever the frame rate.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from pftrack.cli import main
from pftrack.io.video import FrameSource
from pftrack.synthetic import Scene, make_scene
from tests.io.decode import grabs_before_failure
from tests.io.test_estimated_count import VARIABLE, write_vfr

pytest.importorskip("av")


def said_of(n: int) -> str:
    """The warning's words for a 10 fps, 6 s file whose decoding stopped after frame `n`."""
    return (
        f"ended after {n} frames but its container says 6.0 s (frame {n} is at "
        f"{(n - 1) / 10:.1f} s): a truncated or damaged file?"
    )


@pytest.fixture(scope="module")
def scene() -> Scene:
    return make_scene(60, 160, 120, n_walkers=2, rng=1)


def cut(path: Path, keep: float) -> Path:
    """`path`'s first `keep` of its bytes, written beside it (a copy cut short)."""
    data = path.read_bytes()
    out = path.with_name(f"cut_{path.name}")
    out.write_bytes(data[: int(len(data) * keep)])
    return out


@pytest.fixture
def whole(scene: Scene, tmp_path: Path) -> Path:
    return write_vfr(tmp_path / "v.mkv", scene, [100] * 60)  # 10 fps, 6.0 s


def frames_and_warnings(video: Path) -> tuple[int, list[str]]:
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        n = sum(1 for _ in FrameSource(video))
    return n, [str(w.message) for w in said]


def test_a_whole_file_is_not_called_damaged(whole: Path) -> None:
    assert frames_and_warnings(whole) == (60, [])


def test_reading_a_cut_file_names_it_and_its_last_frame(whole: Path) -> None:
    video = cut(whole, 0.5)
    n = grabs_before_failure(video)
    assert 1 < n < 50  # the test's premise: FFmpeg decodes the frames before the cut
    assert frames_and_warnings(video) == (n, [f"{video} {said_of(n)}"])


@pytest.mark.parametrize("given", [False, True])
def test_pftrack_track_of_a_cut_file_warns_and_exits_0(
    whole: Path, tmp_path: Path, given: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    # the built-in detector's spread bootstrap counts the frames first (recount): was unsaid
    # there too; with detections, the frames are read once, to the end
    video = cut(whole, 0.5)
    det = tmp_path / "det.txt"
    det.write_text("1,-1,20,20,20,40,0.9,-1,-1,-1\n")
    args = ["--detections", str(det)] if given else []
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", VARIABLE)
        code = main(["-q", "track", str(video), *args, "--out", str(tmp_path / "t.txt")])
    assert code == 0
    err = capsys.readouterr().err
    assert err.count(f"warning: {video} {said_of(grabs_before_failure(video))}\n") == 1, err
