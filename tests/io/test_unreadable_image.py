"""An image of a folder that cannot be read stands in by the frame before, as a video's frame.

A user trial (trial61): one broken image at frame 298 of a 300-image folder ended the run with
``cannot read image ...``, every frame tracked before it lost (on a big folder, hours). A
video's frame that fails to decode was already replaced by the frame before, with one warning
(``FrameSource``). An image folder now does the same: an image that cannot be read (empty, cut
short, not an image, a folder or a broken link named like one) stands in by the frame before,
or by a black frame when no image before it can be read (marked as a stand-in, as a video's
damaged start: ``FrameSource.lead_black``); the first is said as it is met, naming the file and
why, the pass's count and first names at its end only if there were more. An image of another
size is still refused, naming it (another picture, not a damaged one); a folder none of whose
images can be read is one error.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.io.video import FrameSequence, FrameSource
from pftrack.synthetic import make_scene
from pftrack.tracking.run import track_path


def _folder(tmp_path: Path, n: int = 8) -> Path:
    """`n` 6x8 PNGs ``1.png`` ... whose pixels are their number * 10."""
    folder = tmp_path / "imgs"
    folder.mkdir()
    for k in range(1, n + 1):
        cv2.imwrite(str(folder / f"{k}.png"), np.full((6, 8, 3), k * 10, np.uint8))
    return folder


def _said(fn: Callable[[], object]) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fn()
    return [str(w.message) for w in caught]


def _break(path: Path, how: str) -> None:
    if how == "empty":
        path.write_bytes(b"")
    elif how == "cut":  # a copy cut short: a PNG's header without its data
        path.write_bytes(path.read_bytes()[:40])
    elif how == "text":
        path.write_bytes(b"not an image at all")
    else:
        path.unlink()
        path.symlink_to(path.parent / "gone.png")


@pytest.mark.parametrize("how", ["empty", "cut", "text", "broken link"])
def test_an_image_that_cannot_be_read_stands_in_by_the_frame_before(
    tmp_path: Path, how: str
) -> None:
    folder = _folder(tmp_path)
    _break(folder / "7.png", how)
    source = FrameSource(folder)
    frames: list[np.ndarray] = []
    said = _said(lambda: frames.extend(source))
    assert [int(f[0, 0, 0]) for f in frames] == [10, 20, 30, 40, 50, 60, 60, 80]
    assert len(said) == 1, said
    assert said[0].startswith(f"frame 7: cannot read image {folder / '7.png'}: ")
    assert said[0].endswith(
        "; the frame before stands in for it, so the later frames keep their numbers"
    )
    assert source.lead_black == 0


def test_the_first_images_stand_in_by_black_frames_and_are_counted(tmp_path: Path) -> None:
    """Frame 1 black, as a video's damaged start; the size is the first readable image's."""
    folder = _folder(tmp_path)
    _break(folder / "1.png", "empty")
    _break(folder / "2.png", "text")
    source = FrameSource(folder)
    assert source.lead_black == 2 and (source.width, source.height) == (8, 6)
    frames: list[np.ndarray] = []
    said = _said(lambda: frames.extend(source))
    assert [int(f[0, 0, 0]) for f in frames] == [0, 0, 30, 40, 50, 60, 70, 80]
    assert frames[0].shape == (6, 8, 3)
    assert said == [
        f"frame 1: cannot read image {folder / '1.png'}: it is empty (0 bytes); a black frame "
        "(no image before it can be read) stands in for it, so the later frames keep their "
        "numbers",
        f"{folder}: 2 images could not be read (1.png, 2.png; frames 1-2): the frame before "
        "stands in for each (a black frame for frames 1-2: no image before it can be read)",
    ]


def test_many_are_said_once_with_their_count_and_first_names(tmp_path: Path) -> None:
    """The first as met; at the end of the pass the count and first three names; a second
    pass over the same source says nothing again."""
    folder = _folder(tmp_path, 12)
    for k in (3, 5, 6, 9, 11):
        _break(folder / f"{k}.png", "empty")
    source = FrameSource(folder)
    said = _said(lambda: list(source))
    assert len(said) == 2, said
    assert said[0].startswith("frame 3: cannot read image")
    assert said[1] == (
        f"{folder}: 5 images could not be read (3.png, 5.png, 6.png, ...; frames 3, 5-6, 9, "
        "11): the frame before stands in for each"
    )
    assert _said(lambda: list(source)) == []


def test_chosen_frames_and_items_are_the_frames_iterating_gives(tmp_path: Path) -> None:
    """frames_at (a bootstrap's frames) and FrameSequence (the tracklet linker's) give the same
    stand-ins as a pass: the nearest image before that can be read, or black."""
    folder = _folder(tmp_path)
    for k in (1, 4, 5):
        _break(folder / f"{k}.png", "text")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        every = list(FrameSource(folder))
        at = FrameSource(folder).frames_at([0, 3, 4, 7])
        items = FrameSequence(folder)
        chosen = [items[i] for i in (4, 0, 3)]
    assert [int(f[0, 0, 0]) for f in every] == [0, 20, 30, 30, 30, 60, 70, 80]
    assert all(np.array_equal(a, every[i]) for a, i in zip(at, [0, 3, 4, 7], strict=True))
    assert all(np.array_equal(a, every[i]) for a, i in zip(chosen, [4, 0, 3], strict=True))


def test_a_loop_under_w_error_stops_at_the_image(tmp_path: Path) -> None:
    """Said before the stand-in is given: a loop that makes warnings errors stops there."""
    folder = _folder(tmp_path)
    _break(folder / "5.png", "empty")
    given = 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=r"^frame 5: cannot read image .*5\.png"):
            for _ in FrameSource(folder):
                given += 1
    assert given == 4


def test_a_folder_none_of_whose_images_can_be_read_is_one_error(tmp_path: Path) -> None:
    folder = _folder(tmp_path, 3)
    for k in (1, 2, 3):
        _break(folder / f"{k}.png", "text")
    with pytest.raises(ValueError) as info:
        FrameSource(folder)
    assert str(info.value) == (
        f"cannot read any of the 3 images in folder {folder}: 1.png: not an image OpenCV can "
        "decode (damaged?)"
    )


def test_an_image_of_another_size_is_still_refused_naming_the_first_that_reads(
    tmp_path: Path,
) -> None:
    """Another size is another picture (a stray file, another camera), not a damaged one:
    refused as before, against the first image that can be read."""
    folder = _folder(tmp_path)
    _break(folder / "1.png", "empty")
    cv2.imwrite(str(folder / "6.png"), np.zeros((12, 16, 3), np.uint8))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=re.escape(
            f"image {folder / '6.png'} is 16x12 but 2.png is 8x6: every image of a folder "
            "must have one size"
        )):  # fmt: skip
            list(FrameSource(folder))


@pytest.mark.parametrize("threads", [True, False], ids=["threads", "no threads"])
def test_a_run_tracks_every_frame_past_a_broken_image(tmp_path: Path, threads: bool) -> None:
    """The trial's case, small: a broken image near the end of a folder (was: the run ended
    with an error at it); then the first image broken too, whose black stand-in is not taken
    for a blank video ("frame 1 is blank ... placeholder frames?")."""
    folder = make_scene(n_frames=40, width=160, height=120, rng=0).write_images(tmp_path / "img")
    images = sorted(folder.iterdir())
    images[37].write_bytes(images[37].read_bytes()[:300])  # frame 38 of 40, cut short
    runs = []
    said = _said(lambda: runs.append(track_path(folder, threads=threads)))
    assert runs[0].n_frames == 40 and 38 in runs[0].rows[:, 0], runs[0]
    assert len(said) == 1 and said[0].startswith(f"frame 38: cannot read image {images[37]}: ")
    images[0].write_bytes(b"")
    said = _said(lambda: runs.append(track_path(folder, threads=threads)))
    assert runs[1].n_frames == 40
    assert len(said) == 2 and said[0].startswith("frame 1: cannot read image"), said
