"""An H.264 file whose decoder drops frames without failing a read is said, naming the file.

One packet of a 60-frame H.264 MP4 overwritten with zeros: FFmpeg's decoder gives no frame
for it, nor for the frames that refer to it up to the next key frame, and no read fails
(OpenCV reads 49 frames). The reader cannot stand in for them as it does for a read that
fails (:func:`pftrack.io.video._resume`): it learns of the gap only from the next frame's
time stamp. It now says so once, naming the file and the frames, instead of only "its header
says 60 frames but it holds 49 (counted): a truncated or damaged file" at the end; the frames
are numbered by counting, as before (docs/robustness.md).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import av
import numpy as np
import pytest

from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene

SKIPPED = "the time stamps skip"


def _h264(path: Path, zeroed: int | None, *, b_frames: int = 0) -> Path:
    """60 frames of a scene at 10 fps, a key frame every 12; packet `zeroed` (1-based) zeros."""
    frames = list(make_scene(n_frames=60, rng=0).frames)
    with av.open(str(path), "w", format="mp4") as out:
        stream = out.add_stream("libx264", rate=10, options={"g": "12", "bf": str(b_frames)})
        stream.height, stream.width = frames[0].shape[:2]
        stream.pix_fmt = "yuv420p"
        n = 0
        for frame in [*frames, None]:
            picture = None if frame is None else av.VideoFrame.from_ndarray(frame, format="bgr24")
            for packet in stream.encode(picture):
                n += 1
                if n == zeroed:
                    damaged = av.Packet(bytes(packet.size))
                    damaged.pts, damaged.dts = packet.pts, packet.dts
                    damaged.time_base, damaged.stream = packet.time_base, stream
                    packet = damaged
                out.mux(packet)
    return path


def _read(path: Path) -> tuple[list[np.ndarray], list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frames = list(FrameSource(path))
    return frames, [str(w.message) for w in caught]


@pytest.mark.parametrize("b_frames", [0, 3])
def test_frames_a_decoder_dropped_are_said_once_naming_the_file(
    b_frames: int, tmp_path: Path
) -> None:
    path = _h264(tmp_path / "dropped.mp4", zeroed=25, b_frames=b_frames)
    frames, said = _read(path)
    assert 45 <= len(frames) < 60  # numbered by counting, as before
    skipped = [m for m in said if SKIPPED in m]
    assert len(skipped) == 1, said  # was: none
    first = 25 - (b_frames > 0)  # the first frame missing (B-frames: the one before it too)
    assert skipped[0].startswith(
        f"{path}: the time stamps skip from frame {first - 1} to frame {first + 11}: frames "
        f"{first}-{first + 10} did not come from the decoder, without an error"
    )
    assert skipped[0].endswith("11 early against detections or ground truth of the whole video")


def test_an_intact_h264_file_says_nothing(tmp_path: Path) -> None:
    frames, said = _read(_h264(tmp_path / "intact.mp4", zeroed=None))
    assert len(frames) == 60 and said == []


def test_a_frame_that_fails_after_a_dropped_one_is_read_past(tmp_path: Path) -> None:
    """The stamps jumped where the decoder dropped frames, and the reader stopped resuming: a
    later frame that failed to decode ended the run there (stop 66's ``flip_h.mp4``: 18 of 50
    frames). Now the stamps are counted from the jump on, and the reader goes on past the
    failure as in an undamaged stream, the frame before standing in; the count agrees."""
    import cv2

    dropped = _h264(tmp_path / "dropped.mp4", zeroed=25).read_bytes()
    n = len(dropped)
    for seed in range(40):  # bytes flipped late in the file until a read there fails
        rng = np.random.default_rng(seed)
        damaged = bytearray(dropped)
        for i in rng.integers(int(n * 0.7), int(n * 0.95), 60):
            damaged[i] ^= 0xFF
        path = tmp_path / f"flipped{seed}.mp4"
        path.write_bytes(bytes(damaged))
        capture = cv2.VideoCapture(str(path))
        reads = [capture.read()[0] for _ in range(62)]
        capture.release()
        if False in reads[:48] and any(reads[reads.index(False) :]):
            break
    else:
        pytest.skip("no flip made a read fail with frames after it (another FFmpeg?)")
    failed = reads.index(False)
    frames, said = _read(path)
    assert len(frames) > failed + 1  # was: len(frames) == failed, the run ended there
    assert len(frames) >= sum(reads)  # every frame that decodes, and stand-ins
    assert any("could not be decoded" in m for m in said)
    assert any(SKIPPED in m for m in said)
    with pytest.warns(UserWarning, match="its header says 60 frames but it holds"):
        counted = FrameSource(path).recount()
    assert counted == len(frames)  # the count before a run agrees


def test_the_dropped_frames_are_said_after_a_recount(tmp_path: Path) -> None:
    """`pftrack track` recounts such a file before its tracking pass (the header's 60 against
    49 found); the skip is still said then, against the header's count, not the recount's."""
    path = _h264(tmp_path / "dropped.mp4", zeroed=25)
    source = FrameSource(path)
    with pytest.warns(UserWarning, match="its header says 60 frames but it holds"):
        assert source.recount() == 49
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert len(list(source)) == 49
    assert sum(SKIPPED in str(w.message) for w in caught) == 1
