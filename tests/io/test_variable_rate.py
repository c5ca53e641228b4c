"""A variable-frame-rate video is read at one rate: said once, with the spread of its steps.

A phone's video (frames 100 and 200 ms apart) has its average rate in its header (6.78 fps for
40 such frames in an MP4), which ``--render`` and ``pftrack render`` wrote its video at, its
frames evenly spaced, and the tracker takes every step between frames as one: without a word.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import write_mot
from pftrack.io.video import UNEVEN_FIRST_CHECK, FrameSource
from pftrack.synthetic import Scene, make_scene
from tests.io.test_estimated_count import write_vfr

pytest.importorskip("av")


@pytest.fixture(scope="module")
def scene() -> Scene:
    return make_scene(40, 160, 120, n_walkers=2, rng=1)


@pytest.mark.parametrize("suffix", [".mp4", ".mkv"])
def test_uneven_time_stamps_are_said_once_with_the_rate_used(
    scene: Scene, tmp_path: Path, suffix: str
) -> None:
    video = write_vfr(tmp_path / f"vfr{suffix}", scene, [100, 200] * 20)
    source = FrameSource(video)
    with pytest.warns(UserWarning, match="variable frame rate") as said:
        assert sum(1 for _ in source) == 40
    (message,) = [str(w.message) for w in said if "variable" in str(w.message)]
    assert str(video) in message
    assert f"{source.fps:g} fps" in message  # the rate used, from the header
    assert "100 to 200 ms apart" in message  # the spread
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sum(1 for _ in source) == 40  # once per source


@pytest.mark.parametrize("gaps", [[40] * 40, [33, 34, 33] * 13 + [33], [40] * 38 + [80, 40]])
def test_even_time_stamps_are_not_said(scene: Scene, tmp_path: Path, gaps: list[int]) -> None:
    """Constant rates (29.97 fps stamped in whole milliseconds: 33 and 34 ms) and one dropped
    frame in 40 are no variable rate."""
    video = write_vfr(tmp_path / "cfr.mkv", scene, gaps, rate=25)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sum(1 for _ in FrameSource(video)) == 40


def test_a_rate_given_is_not_said(scene: Scene, tmp_path: Path) -> None:
    video = write_vfr(tmp_path / "vfr.mp4", scene, [100, 200] * 20)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sum(1 for _ in FrameSource(video, fps=7)) == 40


def test_track_says_it_once(
    scene: Scene, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    video = write_vfr(tmp_path / "vfr.mp4", scene, [100, 200] * 20)
    det = scene.truth.copy()
    det[:, 1] = -1
    write_mot(tmp_path / "det.txt", det)
    code = main(["track", str(video), "--detections", str(tmp_path / "det.txt"),
                 "--out", str(tmp_path / "t.txt"), "--particles", "30"])  # fmt: skip
    assert code == 0
    assert capsys.readouterr().err.count("variable frame rate") == 1


def test_it_is_said_as_soon_as_the_stamps_show_it_with_their_figures(tmp_path: Path) -> None:
    """Said once 50 frames were read, naming them (was: once the whole file was, a long video's
    whole run without a word), not again at the end."""
    long = make_scene(120, 96, 64, n_walkers=1, rng=2)
    video = write_vfr(tmp_path / "vfr.mp4", long, [100, 200] * 60)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        for n, _ in enumerate(FrameSource(video), start=1):
            if n == UNEVEN_FIRST_CHECK:
                assert len(said) == 1  # at the frame that showed it
    (message,) = [str(w.message) for w in said]
    assert f"its first {UNEVEN_FIRST_CHECK} frames are 100 to 200 ms apart" in message


def test_a_rate_that_varies_later_is_said_with_the_whole_files_figures(tmp_path: Path) -> None:
    """Even for its first 50 frames, uneven after: said at the end, of all its frames."""
    long = make_scene(90, 96, 64, n_walkers=1, rng=2)
    video = write_vfr(tmp_path / "late.mp4", long, [100] * 60 + [100, 300] * 15)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        for n, _ in enumerate(FrameSource(video), start=1):
            if n == 89:
                assert not said
    (message,) = [str(w.message) for w in said]
    assert "variable frame rate: its frames are 100 to 300 ms apart (median 100 ms)" in message


def test_track_says_it_while_tracking_not_after(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``pftrack track`` printed the warnings raised while tracking once the run was over (an
    hour's video: an hour late); each is now printed as it is raised."""
    long = make_scene(120, 96, 64, n_walkers=1, rng=2)
    video = write_vfr(tmp_path / "vfr.mp4", long, [100, 200] * 60)
    seen: list[str] = []  # stderr by the 60th frame read
    iterate = FrameSource.__iter__

    def watched(self: FrameSource) -> Iterator[np.ndarray]:
        for n, frame in enumerate(iterate(self), start=1):
            if n == 60 and not seen:
                seen.append(capsys.readouterr().err)
            yield frame

    monkeypatch.setattr(FrameSource, "__iter__", watched)
    assert main(["-q", "track", str(video), "--out", str(tmp_path / "t.txt")]) == 0
    assert seen and seen[0].count("variable frame rate: its first 50 frames") == 1
    assert "variable frame rate" not in capsys.readouterr().err  # not again at the end


def test_a_warning_into_a_closed_stderr_costs_no_output(tmp_path: Path) -> None:
    """Printed while tracking, a warning into a pipe whose reader left (``2>&1 | head -1``
    after its line) must not end the run: the tracks are written all the same."""
    import os
    import subprocess
    import sys

    long = make_scene(60, 96, 64, n_walkers=1, rng=2)
    video = write_vfr(tmp_path / "vfr.mp4", long, [100, 200] * 30)
    argv = [sys.executable, "-m", "pftrack", "-q", "track", str(video), "--particles", "30"]
    read, write = os.pipe()
    os.close(read)  # closed before the command writes
    try:
        run = subprocess.run([*argv, "--out", str(tmp_path / "closed.txt")], stderr=write,
                             stdout=subprocess.DEVNULL, check=False, timeout=300)  # fmt: skip
    finally:
        os.close(write)
    assert run.returncode == 0
    assert main([*argv[3:], "--out", str(tmp_path / "open.txt")]) == 0
    assert (tmp_path / "closed.txt").read_bytes() == (tmp_path / "open.txt").read_bytes() != b""
