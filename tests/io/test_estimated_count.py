"""A container whose frame count is FFmpeg's estimate (Matroska) is not held to it.

A user trial's variable-frame-rate ``.mkv`` of 60 frames: OpenCV said 53, and ``pftrack track
--detections`` refused the detections of frames 54-60 as "a longer video's"; another said 276,
and every run warned of "a truncated or damaged file".
"""

from __future__ import annotations

import fractions
import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot, write_mot
from pftrack.io.video import FrameSource
from pftrack.synthetic import Scene, make_scene
from tests.io.test_video import grey_mjpg

av = pytest.importorskip("av")


@pytest.fixture(scope="module")
def scene() -> Scene:
    return make_scene(60, 160, 120, n_walkers=2, rng=1)


def write_vfr(path: Path, scene: Scene, gaps_ms: list[int], rate: int = 10) -> Path:
    """H.264 in Matroska, frame k stamped at sum(gaps_ms[:k]) ms (`rate`: the stream's own)."""
    out = av.open(str(path), "w")
    stream = out.add_stream("libx264", rate=rate)
    stream.width, stream.height, stream.pix_fmt = scene.width, scene.height, "yuv420p"
    stream.time_base = fractions.Fraction(1, 1000)
    # the encoder's too: in its 1 / rate, x264's stamps of an MP4 over 40 frames went back
    stream.codec_context.time_base = stream.time_base
    t = 0
    for frame, gap in zip(scene.frames, gaps_ms, strict=True):
        f = av.VideoFrame.from_ndarray(frame, format="bgr24")
        f.pts = t
        for packet in stream.encode(f):
            out.mux(packet)
        t += gap
    for packet in stream.encode():
        out.mux(packet)
    out.close()
    return path


VARIABLE = ".* variable frame rate"  # 100 then 20 ms: said (test_variable_rate), no damage


@pytest.mark.filterwarnings(f"ignore:{VARIABLE}")
def test_detections_of_every_decoded_frame_are_taken(scene: Scene, tmp_path: Path) -> None:
    video = write_vfr(tmp_path / "vfr.mkv", scene, [100] * 50 + [20] * 10)
    source = FrameSource(video)
    assert not source.count_known and 0 < source.n_frames < 60  # the estimate is short
    assert sum(1 for _ in FrameSource(video)) == 60
    det = scene.truth.copy()
    det[:, 1] = -1
    write_mot(tmp_path / "det.txt", det)
    out = tmp_path / "t.txt"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning of a short or damaged file either
        warnings.filterwarnings("ignore", VARIABLE)
        code = main(["-q", "track", str(video), "--detections", str(tmp_path / "det.txt"),
                     "--out", str(out), "--particles", "30"])  # fmt: skip
    assert code == 0
    assert read_mot(out)[:, 0].max() > source.n_frames  # rows of the frames past the estimate


def test_a_long_estimate_is_not_called_damage(scene: Scene, tmp_path: Path) -> None:
    video = write_vfr(tmp_path / "long.mkv", scene, [20] * 50 + [500] * 10, rate=50)
    source = FrameSource(video)
    assert not source.count_known and source.n_frames > 60
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        assert sum(1 for _ in source) == 60
    # its variable rate is said (test_variable_rate), no damage
    assert [str(w.message).split(": ")[1] for w in said] == ["variable frame rate"]


def test_counted_containers_and_folders_keep_their_count(scene: Scene, tmp_path: Path) -> None:
    assert FrameSource(scene.write_video(tmp_path / "s.avi")).count_known
    assert FrameSource(scene.write_video(tmp_path / "s.mp4")).count_known
    assert FrameSource(scene.write_images(tmp_path / "img")).count_known
    assert np.array_equal(
        next(iter(FrameSource(tmp_path / "img"))), scene.frames[0]
    )  # the folder is the scene's


def test_a_rate_the_header_lacks_comes_from_the_time_stamps(
    scene: Scene, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A header "rate" of 1000 (Matroska's time base, as OpenCV reports it for some files):
    the frames' time stamps give the rate. Was: 25 fps, said only as "from default", and a
    render of a 10 fps video played 2.5 times too fast."""
    video = write_vfr(tmp_path / "ten.mkv", scene, [100] * 60)
    probe = FrameSource._probe_file

    def time_base_as_rate(path: Path) -> tuple[np.ndarray, float, int, int]:
        first, _, count, rotation = probe(path)
        return first, 1000.0, count, rotation

    monkeypatch.setattr(FrameSource, "_probe_file", staticmethod(time_base_as_rate))
    source = FrameSource(video)
    assert (source.fps, source.fps_origin) == (pytest.approx(10.0), "time stamps")


def test_a_rate_of_1000_or_more_is_said_not_taken_in_silence(tmp_path: Path) -> None:
    path = grey_mjpg(tmp_path / "fast.avi", 1000.0, 64, 48)
    with pytest.warns(UserWarning, match="frame rate 1000 is taken for none .* 25 fps assumed"):
        source = FrameSource(path)
    assert (source.fps, source.fps_origin) == (25.0, "default")
    assert FrameSource(path, fps=1000.0).fps == 1000.0  # given: taken, without a word
