"""A video output replaces only a video pftrack wrote: a user's video there is refused.

``pftrack track --render mine.mp4`` and ``pftrack render ... --out mine.mp4`` replaced any
file at that path that was not an input of the run, with exit status 0: a user's video typed
for the output was gone. Every video :class:`~pftrack.io.video_writer.VideoWriter` writes now
carries :data:`~pftrack.io.video_writer.RENDER_MARK` (an MP4's ``comment`` tag, an AVI's header
padding), and the output checks replace an existing non-empty video only when it has it, as
``pftrack batch`` replaces only the files an earlier batch's sidecar names.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.video_writer import VideoWriter, is_render
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("inputs")
    scene = make_scene(n_frames=8, rng=0)
    return {"video": scene.write_video(d / "v.avi"), "gt": scene.write_truth(d / "gt.txt")}


def _users_video(path: Path) -> bytes:
    """A video pftrack did not write (OpenCV's writer, as a camera's or an editor's file)."""
    make_scene(n_frames=3, rng=1).write_video(path)
    return path.read_bytes()


def _argv(command: str, inputs: dict[str, Path], video: Path, tmp_path: Path) -> list[str]:
    if command == "track":
        return ["-q", "track", str(inputs["video"]), "--out", str(tmp_path / "t.txt"),
                "--render", str(video), "--particles", "20"]  # fmt: skip
    return ["-q", "render", str(inputs["video"]), str(inputs["gt"]), "--out", str(video)]


@pytest.mark.filterwarnings("ignore::UserWarning")  # an 8-frame scene's notes, not the subject
@pytest.mark.parametrize("command", ["track", "render"])
@pytest.mark.parametrize("suffix", [".mp4", ".avi"])
def test_a_users_video_is_refused_and_a_render_replaced(
    command: str,
    suffix: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    video = tmp_path / f"mine{suffix}"
    mine = _users_video(video)
    link = tmp_path / f"link{suffix}"
    link.symlink_to(video.name)
    option = "--render" if command == "track" else "--out"
    for given in (video, link):
        assert main(_argv(command, inputs, given, tmp_path)) == 2
        assert capsys.readouterr().err == (
            f"pftrack {command}: error: {option} {given} is an existing file that pftrack did "
            "not write (a video of yours?), and would be replaced: move it, give another "
            "name, or pass --force\n"
        )
        assert video.read_bytes() == mine  # was: replaced, exit status 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([video.name, link.name])
    video.unlink()
    video.write_bytes(b"")  # an empty file: nothing to lose
    for _ in range(2):  # then the render just written is pftrack's: replaced
        assert main(_argv(command, inputs, video, tmp_path)) == 0, capsys.readouterr().err
        assert is_render(video)
        capture = cv2.VideoCapture(str(video))
        assert capture.read()[0]  # the mark leaves the video readable
        capture.release()


@pytest.mark.parametrize("suffix", [".mp4", ".avi"])
def test_is_render_tells_a_writers_video_from_others(suffix: str, tmp_path: Path) -> None:
    ours, theirs = tmp_path / f"ours{suffix}", tmp_path / f"theirs{suffix}"
    frames = [np.full((32, 48, 3), 40 * i, np.uint8) for i in range(4)]
    with VideoWriter(ours, fps=5) as writer:
        for frame in frames:
            writer.write(frame)
    _users_video(theirs)
    text = tmp_path / "t.txt"
    text.write_text("1,1,0,0,1,1,1,-1,-1,-1\n")
    assert is_render(ours)
    assert not any(is_render(p) for p in (theirs, text, tmp_path / "none.mp4", tmp_path))
    capture = cv2.VideoCapture(str(ours))
    read = [capture.read()[1] for _ in frames]
    capture.release()
    assert all(f is not None and f.shape == (32, 48, 3) for f in read)  # every frame there
