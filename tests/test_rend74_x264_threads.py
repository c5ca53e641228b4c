"""x264 on two frame threads (stop 74, rend74): the pictures of one thread, the same file each run.

``VideoWriter`` encodes an ``.mp4`` on a fixed two x264 frame threads, so that the encode leaves
the render worker's thread. What the change may alter of a video, and what it may not: the
pictures are those one thread encodes (x264 at ``ultrafast``, constant rate factor: no rate
control across frames in flight), and the bytes differ from one thread's only in x264's
settings string (``threads=2``), the same from run to run.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pftrack.io import video_writer
from pftrack.io.video_writer import VideoWriter
from pftrack.render import TrackRenderer
from tests.io.decode import decode


def _scene(n: int, h: int = 360, w: int = 480, seed: int = 3) -> list[np.ndarray]:
    """Textured blobs crossing a noisy textured background: motion, texture and noise to code."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w]
    ground = (60 + 40 * np.sin(x / 7.0) * np.cos(y / 5.0)).astype(np.int16)
    blobs = rng.uniform([0, 0, 8, 6, 2], [w, h, 30, 40, 9], (6, 5))  # x, y, rx, ry, speed
    frames = []
    for k in range(n):
        image = np.repeat(ground[:, :, None], 3, axis=2)
        for i, (bx, by, rx, ry, v) in enumerate(blobs):
            inside = ((x - (bx + v * k) % w) / rx) ** 2 + ((y - by) / ry) ** 2 <= 1
            image[inside] = (40 * i % 256, 200 - 25 * i, 90 + 20 * i)
        image = image + rng.integers(-12, 13, image.shape)
        frames.append(np.clip(image, 0, 255).astype(np.uint8))
    return frames


def _write(path: Path, frames: list[np.ndarray]) -> bytes:
    with VideoWriter(path, 7) as writer:
        for f in frames:
            writer.write(f)
    return path.read_bytes()


@pytest.mark.parametrize(("h", "w"), [(360, 480), (361, 201)])
def test_two_frame_threads_encode_one_threads_pictures(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, h: int, w: int
) -> None:
    frames = _scene(40, h, w)
    threaded = _write(tmp_path / "two.mp4", frames)
    monkeypatch.setattr(video_writer, "_X264_THREADS", 1)
    one = _write(tmp_path / "one.mp4", frames)
    assert b" threads=2 " in threaded and b" threads=1 " in one  # the count is fixed, not auto
    _, got_two = decode(tmp_path / "two.mp4")
    _, got_one = decode(tmp_path / "one.mp4")
    assert len(got_two) == len(got_one) == 40
    for k, (a, b) in enumerate(zip(got_two, got_one, strict=True)):
        assert np.array_equal(a, b), f"frame {k + 1} differs"
    # nothing else differs: the coded frames are one thread's, byte for byte
    assert len(threaded) == len(one)
    assert threaded.replace(b" threads=2 ", b" threads=1 ", 1) == one


@pytest.mark.parametrize(("h", "w"), [(75, 101), (358, 640)])
def test_frames_under_360_rows_are_encoded_on_one_thread(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, h: int, w: int
) -> None:
    """There two frame threads bound the motion vectors, and would change the pictures."""
    frames = _scene(40, h, w)
    default = _write(tmp_path / "default.mp4", frames)
    assert b" threads=1 " in default
    monkeypatch.setattr(video_writer, "_X264_THREADS", 1)
    assert _write(tmp_path / "one.mp4", frames) == default


def test_a_threaded_encode_writes_the_same_bytes_each_run(tmp_path: Path) -> None:
    frames = _scene(30)
    first = _write(tmp_path / "a.mp4", frames)
    assert _write(tmp_path / "b.mp4", frames) == first


def test_a_rendered_video_is_the_same_file_each_run(tmp_path: Path) -> None:
    """``TrackRenderer`` (``--render``): its worker and x264's two threads, the same bytes."""

    class Walker:
        def __init__(self, tid: int, box: np.ndarray, since: int) -> None:
            self.id, self.box_xywh, self.time_since_update = tid, box, since

    frames = _scene(30)

    def render(name: str) -> bytes:
        renderer = TrackRenderer(tmp_path / name, 7)
        for k, frame in enumerate(frames):
            tracks = [
                Walker(i, np.array([10.0 + 5 * k + 30 * i, 20.0 + 9 * i, 18.0, 40.0]), k % (i + 2))
                for i in range(5)
            ]
            renderer.add(frame, tracks)
        return renderer.close().read_bytes()

    first = render("a.mp4")
    assert render("b.mp4") == first
    _, got = decode(tmp_path / "a.mp4")
    assert len(got) == 30
