"""An image folder's odd-sized image is refused when the folder is opened, not when reached.

Was (frames61's note): an image of another size than the first was found only when read, after
every frame before it had been tracked (minutes, on a big folder). Opening the folder now reads
each PNG's and JPEG's size from its header (``_header_size``: a few bytes a file; 10 000 files
0.31-0.50 s here, against 48-280 s to decode them, docs/io.md) and refuses the first odd one
in the same words as the read did. An image whose header cannot be read (empty, not an image)
is left to the read, which stands a frame in for it as before; so is a size that is the first's
turned, which an EXIF orientation may turn back as OpenCV reads it.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.video import FrameSource, _header_size


def _folder(tmp_path: Path, suffix: str = ".png", n: int = 8) -> Path:
    """`n` 8x6 images ``1.png`` ... whose pixels are their number * 5."""
    folder = tmp_path / "imgs"
    folder.mkdir()
    for k in range(1, n + 1):
        cv2.imwrite(str(folder / f"{k}{suffix}"), np.full((6, 8, 3), k * 5, np.uint8))
    return folder


def _turned_jpeg(path: Path, height: int, width: int, orientation: int) -> None:
    """A `width` x `height` JPEG with an EXIF orientation tag (6: turned 90 degrees as read)."""
    ok, data = cv2.imencode(".jpg", np.full((height, width, 3), 99, np.uint8))
    assert ok
    tiff = b"MM\x00*\x00\x00\x00\x08\x00\x01\x01\x12\x00\x03\x00\x00\x00\x01"
    tiff += orientation.to_bytes(2, "big") + bytes(6)
    app1 = b"\xff\xe1" + (8 + len(tiff)).to_bytes(2, "big") + b"Exif\x00\x00" + tiff
    path.write_bytes(data.tobytes()[:2] + app1 + data.tobytes()[2:])


@pytest.mark.parametrize("suffix", [".png", ".jpg"])
def test_an_image_of_another_size_is_refused_when_the_folder_is_opened(
    tmp_path: Path, suffix: str
) -> None:
    folder = _folder(tmp_path, suffix)
    cv2.imwrite(str(folder / f"7{suffix}"), np.zeros((12, 16, 3), np.uint8))
    with pytest.raises(ValueError) as info:
        FrameSource(folder)  # was: opened, refused only when image 7 was read
    assert str(info.value) == (
        f"image {folder / f'7{suffix}'} is 16x12 but 1{suffix} is 8x6: every image of a folder "
        "must have one size"
    )


def test_the_cli_refuses_it_before_any_frame_is_tracked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = _folder(tmp_path, n=40)
    cv2.imwrite(str(folder / "40.png"), np.zeros((12, 16, 3), np.uint8))
    out = tmp_path / "t.txt"
    read: list[Path] = []  # the images read as frames (was: 39, then the refusal)
    frame_of = FrameSource._read_image
    monkeypatch.setattr(FrameSource, "_read_image", lambda s, p: read.append(p) or frame_of(s, p))
    assert main(["track", str(folder), "--out", str(out)]) == 2
    assert read == []
    captured = capsys.readouterr()
    assert captured.err == (
        f"pftrack track: error: image {folder / '40.png'} is 16x12 but 1.png is 8x6: every "
        "image of a folder must have one size\n"
    )
    assert captured.out == "" and not out.exists()


def test_unreadable_images_still_stand_in_and_a_turned_size_is_left_to_the_read(
    tmp_path: Path,
) -> None:
    """An empty file and a text file named like images: opened, then stood in for as read
    (test_unreadable_image.py); a JPEG stored 6x8 with EXIF orientation 6 is read 8x6 as the
    rest, and tracked; stored 8x6 with it, it is read 6x8 and refused when read, as before."""
    folder = _folder(tmp_path)
    (folder / "3.png").write_bytes(b"")
    (folder / "4.png").write_text("not an image")
    _turned_jpeg(folder / "5.png", 8, 6, 6)  # stored 6 wide, 8 high: read 8x6
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the unreadable images' warning: said elsewhere
        frames = list(FrameSource(folder))
    assert len(frames) == 8 and all(f.shape == (6, 8, 3) for f in frames)
    _turned_jpeg(folder / "5.png", 6, 8, 6)  # stored 8x6: read 6 wide, 8 high
    source = FrameSource(folder)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=re.escape(f"image {folder / '5.png'} is 6x8 but")):
            list(source)


def test_header_sizes(tmp_path: Path) -> None:
    image = np.zeros((6, 8, 3), np.uint8)
    for suffix in (".png", ".jpg", ".bmp"):
        cv2.imwrite(str(tmp_path / f"a{suffix}"), image)
    _turned_jpeg(tmp_path / "exif.jpg", 6, 8, 1)  # an APP1 segment before the frame's
    assert _header_size(tmp_path / "a.png") == (8, 6)
    assert _header_size(tmp_path / "a.jpg") == (8, 6)
    assert _header_size(tmp_path / "exif.jpg") == (8, 6)
    assert _header_size(tmp_path / "a.bmp") is None  # another format: checked when read
    (tmp_path / "cut.jpg").write_bytes((tmp_path / "exif.jpg").read_bytes()[:30])
    (tmp_path / "empty.png").write_bytes(b"")
    assert _header_size(tmp_path / "cut.jpg") is None
    assert _header_size(tmp_path / "empty.png") is None
    assert _header_size(tmp_path / "missing.png") is None
