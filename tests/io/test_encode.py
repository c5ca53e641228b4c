"""The tests' video writer (tests/io/encode.py), read back with tests/io/decode.py."""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

from pftrack.io.video import FrameSource
from pftrack.synthetic import make_scene
from tests.io.decode import decode
from tests.io.encode import encode


@pytest.mark.parametrize(
    ("name", "codec", "pix_fmt", "container"),
    [("v.mp4", "libx264", "yuv420p", None), ("v.ts", "libx264", "yuv420p", "mpegts"),
     ("v.avi", "mjpeg", "yuvj420p", None)],
)  # fmt: skip
def test_every_frame_is_written_at_the_rate_in_the_codec_asked(
    tmp_path: Path, name: str, codec: str, pix_fmt: str, container: str | None
) -> None:
    frames = make_scene(n_frames=6, width=96, height=64, rng=0).frames
    path = encode(tmp_path / name, frames, 5, codec=codec, container=container)
    assert path == tmp_path / name
    info, got = decode(path)
    assert (info.codec, info.pix_fmt) == ({"libx264": "h264"}.get(codec, codec), pix_fmt)
    assert info.average_rate == Fraction(5) and len(got) == 6
    assert got[0].shape == (64, 96, 3)


def test_options_reach_the_encoder_and_rotation_the_display_matrix(tmp_path: Path) -> None:
    av = pytest.importorskip("av")
    frames = make_scene(n_frames=12, width=96, height=64, rng=0).frames
    path = encode(tmp_path / "v.mp4", frames, options={"g": "4", "bf": "0"}, rotation=90)
    with av.open(str(path)) as container:
        packets = [p for p in container.demux(video=0) if p.size]
    assert [k for k, p in enumerate(packets) if p.is_keyframe] == [0, 4, 8]
    source = FrameSource(path)  # turned upright: 64 wide, 96 high
    assert (source.width, source.height) == (64, 96)
