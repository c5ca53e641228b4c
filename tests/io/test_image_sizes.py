"""An image folder's odd-sized image is refused when the folder is opened, not when reached.

Was (frames61's note): an image of another size than the first was found only when read, after
every frame before it had been tracked (minutes, on a big folder). Opening the folder now reads
each PNG's, JPEG's, BMP's, TIFF's and WebP's size from its header (``_header_size``: a few
bytes a file; 10 000 files 0.31-0.50 s here, against 48-280 s to decode them, docs/io.md) and
refuses the first odd one in the same words as the read did (BMP, TIFF and WebP were checked
only when read until left63). An image whose header cannot be read (empty, not an image)
is left to the read, which stands a frame in for it as before; so is a size that is the first's
turned, which an EXIF orientation may turn back as OpenCV reads it.
"""

from __future__ import annotations

import io
import re
import warnings
from pathlib import Path
from typing import Literal

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


@pytest.mark.parametrize("suffix", [".png", ".jpg", ".bmp", ".tif", ".webp"])
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
    assert _header_size(tmp_path / "a.bmp") == (8, 6)  # was None: checked when read
    (tmp_path / "cut.jpg").write_bytes((tmp_path / "exif.jpg").read_bytes()[:30])
    (tmp_path / "empty.png").write_bytes(b"")
    assert _header_size(tmp_path / "cut.jpg") is None
    assert _header_size(tmp_path / "empty.png") is None
    assert _header_size(tmp_path / "missing.png") is None


def _tiff(order: str, kind: int, width: int, height: int) -> bytes:
    """An uncompressed 8-bit grey TIFF in byte order `order` (``II``, ``MM``) whose width and
    height tags are of type `kind` (3 SHORT, 4 LONG); cv2.imwrite writes only ``II``."""
    o: Literal["little", "big"] = "little" if order == "II" else "big"

    def entry(tag: int, typ: int, value: int) -> bytes:
        held = value.to_bytes(2, o) + bytes(2) if typ == 3 else value.to_bytes(4, o)
        return tag.to_bytes(2, o) + typ.to_bytes(2, o) + (1).to_bytes(4, o) + held

    tags = [(256, kind, width), (257, kind, height), (258, 3, 8), (259, 3, 1), (262, 3, 1)]
    pixels_at = 8 + 2 + 12 * (len(tags) + 4) + 4
    tags += [(273, 4, pixels_at), (277, 3, 1), (278, 3, height), (279, 4, width * height)]
    head = (b"II*\x00" if order == "II" else b"MM\x00*") + (8).to_bytes(4, o)
    ifd = len(tags).to_bytes(2, o) + b"".join(entry(*t) for t in tags) + bytes(4)
    return head + ifd + bytes(k % 256 for k in range(width * height))


def _bmp_core(width: int, height: int) -> bytes:
    """A 24-bit BMP with the 12-byte BITMAPCOREHEADER (16-bit width and height)."""
    pixels = bytes((width * 3 + 3) // 4 * 4 * height)
    core = (12).to_bytes(4, "little") + width.to_bytes(2, "little") + height.to_bytes(2, "little")
    core += (1).to_bytes(2, "little") + (24).to_bytes(2, "little")
    size = 14 + 12 + len(pixels)
    return (
        b"BM" + size.to_bytes(4, "little") + bytes(4) + (26).to_bytes(4, "little") + core + pixels
    )


def _written(tmp_path: Path, width: int = 8, height: int = 6) -> dict[str, Path]:
    """BMP, TIFF and WebP files of `width` x `height`: cv2.imwrite's, and the variants it does
    not write (a top-down BMP, a core-header BMP, big-endian TIFFs, SHORT and LONG sizes)."""
    image = np.random.default_rng(0).integers(0, 256, (height, width, 3), dtype=np.uint8)
    files = {
        "bmp": ("a.bmp", image, []),
        "tiff": ("a.tif", image, []),
        "webp VP8L": ("lossless.webp", image, []),  # OpenCV's default: lossless
        "webp VP8": ("lossy.webp", image, [cv2.IMWRITE_WEBP_QUALITY, 80]),
        "webp VP8X": (
            "alpha.webp",
            np.dstack([image, image[..., :1]]),
            [cv2.IMWRITE_WEBP_QUALITY, 80],
        ),
    }
    out = {}
    for kind, (name, pixels, params) in files.items():
        assert cv2.imwrite(str(tmp_path / name), pixels, params)
        out[kind] = tmp_path / name
    data = bytearray(out["bmp"].read_bytes())
    data[22:26] = (-height).to_bytes(4, "little", signed=True)  # rows stored top-down
    (tmp_path / "top_down.bmp").write_bytes(bytes(data))
    out["bmp top-down"] = tmp_path / "top_down.bmp"
    (tmp_path / "core.bmp").write_bytes(_bmp_core(width, height))
    out["bmp core"] = tmp_path / "core.bmp"
    for order in ("II", "MM"):
        for kind, name in ((3, "SHORT"), (4, "LONG")):
            path = tmp_path / f"{order}_{name}.tif"
            path.write_bytes(_tiff(order, kind, width, height))
            out[f"tiff {order} {name}"] = path
    return out


def test_bmp_tiff_and_webp_sizes_are_read_from_their_headers(tmp_path: Path) -> None:
    """Each file's header size is what OpenCV decodes (was: None, checked only when read)."""
    for width, height in ((8, 6), (300, 70)):
        folder = tmp_path / f"{width}x{height}"
        folder.mkdir()
        files = _written(folder, width, height)
        chunks = {p.read_bytes()[12:16] for k, p in files.items() if k.startswith("webp")}
        assert chunks == {b"VP8 ", b"VP8L", b"VP8X"}  # each WebP kind is tested
        for kind, path in files.items():
            decoded = cv2.imread(str(path))
            assert decoded is not None and decoded.shape[:2] == (height, width), kind
            assert _header_size(path) == (width, height), kind


class _Bytes:
    """A file's bytes opened as a file (``_header_size`` calls ``path.open("rb")``): thousands
    of cut and damaged variants, without a slow write of each to the shared disk (2.6 ms)."""

    def __init__(self, data: bytes) -> None:
        self.data = data

    def open(self, mode: str) -> io.BytesIO:
        assert mode == "rb"
        return io.BytesIO(self.data)


def test_a_cut_or_damaged_header_is_not_told_and_never_raises(tmp_path: Path) -> None:
    """Every prefix of each file, and each with one of its first 64 bytes set to 0x00 or 0xFF:
    the size is the true one or None (left to the read), never an exception."""
    for kind, path in _written(tmp_path).items():
        data = path.read_bytes()
        for n in range(len(data)):
            assert _header_size(_Bytes(data[:n])) in (None, (8, 6)), (kind, n)  # type: ignore[arg-type]
        for k in range(64):  # the signature, sizes, and a TIFF directory's offset and start
            for byte in (0x00, 0xFF):
                size = _header_size(_Bytes(data[:k] + bytes([byte]) + data[k + 1 :]))  # type: ignore[arg-type]
                assert size is None or (len(size) == 2 and min(size) > 0), (kind, k, byte)
    probe = tmp_path / "probe"
    probe.write_bytes(b"MM\x00*\xff\xff\xff\xf0")  # a directory past the end
    assert _header_size(probe) is None
    probe.write_bytes(b"RIFF\x00\x00\x00\x00WEBPALPH" + bytes(20))  # an unknown first chunk
    assert _header_size(probe) is None


@pytest.mark.parametrize("suffix", [".bmp", ".tif", ".webp"])
def test_a_cut_image_of_those_formats_is_still_stood_in_for(tmp_path: Path, suffix: str) -> None:
    folder = _folder(tmp_path, suffix)
    data = (folder / f"3{suffix}").read_bytes()
    (folder / f"3{suffix}").write_bytes(data[:20])  # its header cut: not told, left to the read
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the unreadable image's warning: said elsewhere
        frames = list(FrameSource(folder))
    assert len(frames) == 8 and all(f.shape == (6, 8, 3) for f in frames)
