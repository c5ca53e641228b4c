"""Public functions given the wrong type: a one-line TypeError or ValueError naming them.

left63's probe (6 December) called each public function of pftrack and its subpackages with
None, text, a float NaN, a 3-D array and an empty array for each argument. These failed with
an AttributeError, an IndexError of NumPy's or a message of several lines (an array's repr);
pftrack.synthetic's warp_frame failed with OpenCV's assertion over several lines. left64
(6 December) added ``pftrack.render``'s ``ink_scale``, ``draw_trails`` and ``colour_of``:
AttributeError, IndexError, NumPy's "cannot reshape", "truth value ... ambiguous" and
"unhashable type", OpenCV's assertion, "cannot convert float NaN to integer".
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from pftrack import batch, render, synthetic
from pftrack.detection import check_frame, light
from pftrack.io import group_by_frame
from pftrack.io.video import image_files, video_files
from pftrack.tracking.offline import smoothed_copies

_BAD: dict[str, object] = {
    "None": None,
    "str": "x",
    "nan": math.nan,
    "3-D": np.zeros((2, 3, 4)),
    "empty": np.zeros(0),
}
_FRAME = np.full((6, 8, 3), 50, np.uint8)
_ROWS = np.zeros((0, 10))
_AFFINE = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
_CANVAS = np.full((6, 8, 3), 50, np.uint8)  # draw_trails draws in place: not _FRAME
_TRAILS = {1: [(0.0, 0.0), (5.0, 4.0)]}

#: name -> (function, the arguments it is called with, the index of the one replaced)
CALLS: dict[str, tuple[Callable[..., Any], tuple[Any, ...], int]] = {
    "group_by_frame": (group_by_frame, (_ROWS,), 0),
    "smoothed_copies": (smoothed_copies, (_ROWS,), 0),
    "is_dark": (light.is_dark, (_FRAME,), 0),
    "is_blank": (light.is_blank, (_FRAME,), 0),
    "channel_spread": (light.channel_spread, (_FRAME,), 0),
    "frame_gain frame": (light.frame_gain, (_FRAME, _FRAME), 0),
    "frame_gain reference": (light.frame_gain, (_FRAME, _FRAME), 1),
    "sample_step": (light.sample_step, ((6, 8, 3),), 0),
    "fingerprint": (batch.fingerprint, ([],), 0),
    "warp_frame frame": (synthetic.warp_frame, (_FRAME, _AFFINE), 0),
    "warp_frame affine": (synthetic.warp_frame, (_FRAME, _AFFINE), 1),
    "warp_rows rows": (synthetic.warp_rows, (_ROWS, _AFFINE[None], (6, 8)), 0),
    "warp_rows affines": (synthetic.warp_rows, (_ROWS, _AFFINE[None], (6, 8)), 1),
    "warp_rows size": (synthetic.warp_rows, (_ROWS, _AFFINE[None], (6, 8)), 2),
    "move_camera": (synthetic.move_camera, (None,), 0),
    "track_sequence seq": (batch.track_sequence, (None, batch.TrackOptions()), 0),
    "track_sequence options": (batch.track_sequence, (None, None), 1),
    "recover_file options": (batch.recover_file, ("t.txt", None), 1),
    "smooth_file options": (batch.smooth_file, ("t.txt", None), 1),
    "ink_scale": (render.ink_scale, ((6, 8, 3),), 0),
    "colour_of": (render.colour_of, (1,), 0),
    "draw_trails frame": (render.draw_trails, (_CANVAS, _TRAILS), 0),
    "draw_trails trails": (render.draw_trails, (_CANVAS, _TRAILS), 1),
}


@pytest.mark.parametrize("bad", list(_BAD), ids=str)
@pytest.mark.parametrize("name", list(CALLS), ids=str)
def test_a_wrong_argument_is_one_line_naming_the_function(name: str, bad: str) -> None:
    fn, args, k = CALLS[name]
    given = list(args)
    given[k] = _BAD[bad]
    if name == "track_sequence options":  # the sequence checked first: a real one here
        given[0] = batch.SequenceInput(name="s", frames="s/img1")
    if bad == "empty" and name in ("group_by_frame", "fingerprint"):
        assert not fn(*given)  # no rows, no paths: taken, as before
        return
    if bad == "3-D" and name == "warp_frame frame":
        assert fn(*given).shape == (2, 3, 4)  # a 4-channel image: warped, as before
        return
    with pytest.raises((TypeError, ValueError)) as info:
        fn(*given)
    message = str(info.value)
    assert "\n" not in message and message.startswith(name.split()[0]), message


def test_the_checks_keep_what_worked(tmp_path: Path) -> None:
    frame = _FRAME
    assert group_by_frame(_ROWS) == {} and group_by_frame([]) == {}
    rows = np.array([[2, 1, 0, 0, 5, 5, 1, -1, -1, -1], [1, 1, 0, 0, 5, 5, 1, -1, -1, -1.0]])
    assert sorted(group_by_frame(rows)) == [1, 2]
    assert smoothed_copies(rows)[:, 6:].all() and not smoothed_copies(rows)[:, :6].any()
    assert light.is_dark(frame[:, :, ::-1]) is False  # a view of another stride, as before
    assert light.frame_gain(frame, frame.astype(np.float32)) == 1.0  # a model's background
    (tmp_path / "a.mp4").write_bytes(b"")
    (tmp_path / "1.png").write_bytes(b"")
    assert video_files(str(tmp_path)) == [tmp_path / "a.mp4"]  # a str: was an AttributeError
    assert image_files(str(tmp_path)) == [tmp_path / "1.png"]
    entry = batch.fingerprint([str(tmp_path / "a.mp4")])[0]
    assert entry["path"] == str(tmp_path / "a.mp4") and entry["size"] == 0
    with pytest.raises(TypeError, match="^fingerprint: paths must be a sequence of paths"):
        batch.fingerprint(str(tmp_path))  # one path, not a list: was each letter's stat
    moved = synthetic.warp_frame(frame, _AFFINE.tolist())  # a list of lists, as before
    np.testing.assert_array_equal(moved, frame)
    one = np.array([1, 1, 0, 0, 4, 4, 1, -1, -1, -1.0])  # one row, 1-D: taken as before
    np.testing.assert_array_equal(synthetic.warp_rows(one, _AFFINE[None], (6, 8)), one[None])
    with pytest.raises(TypeError, match="^inputs\\[0\\] must be a path .*got ndarray of shape"):
        batch.track_many([np.zeros((2, 3))], out_dir=tmp_path / "o")  # was the array's repr


def _trail_reference(frame: np.ndarray, trails: dict[int, Any]) -> np.ndarray:
    """What draw_trails draws: each id's points rounded, one anti-aliased polyline (OpenCV)."""
    out = frame.copy()
    for tid, pts in trails.items():
        line = np.round(np.asarray(pts, dtype=np.float64)).astype(np.int32).reshape(-1, 1, 2)
        if len(line) > 1:
            cv2.polylines(out, [line], False, render.colour_of(tid), 1, cv2.LINE_AA)
    return out


def test_draw_trails_and_ink_scale_refuse_in_one_line_and_draw_as_before() -> None:
    frame = np.zeros((40, 50, 3), np.uint8)
    trails = {3: [(1, 2), (30.4, 20.6), (45, 38)], np.int64(7): np.array([[0, 39], [49, 0.0]])}
    expected = _trail_reference(frame, trails)
    render.draw_trails(frame, trails)
    np.testing.assert_array_equal(frame, expected)  # drawn in place, as before
    crop = np.zeros((40, 50, 3), np.uint8)
    render.draw_trails(crop[5:30, 5:40], trails)  # a crop's rows: drawn into, as before
    assert crop[5:30, 5:40].any() and not crop[:5].any()
    assert [render.ink_scale(s) for s in ([1080, 1920], np.array([2160, 3840, 3]))] == [2, 4]
    assert render.colour_of(np.int64(7)) == render.colour_of(7) == render.colour_of(7.0)
    with pytest.raises(ValueError, match="^colour_of: track_id is inf, expected a finite"):
        render.colour_of(math.inf)
    refused = {
        "read-only": (np.zeros((4, 5, 3), np.uint8), trails),
        "flipped": (np.zeros((4, 5, 3), np.uint8)[:, ::-1], trails),
        "Fortran": (np.asfortranarray(np.zeros((4, 5, 3), np.uint8)), trails),
        "no pixels": (np.zeros((0, 5, 3), np.uint8), trails),
        "NaN": (frame, {1: [(0, 0), (math.nan, 3)]}),
        "far": (frame, {1: [(0, 0), (1e12, 3)]}),
        "odd": (frame, {1: [1, 2, 3]}),
        "3 columns": (frame, {1: np.zeros((3, 3))}),
        "text": (frame, {1: "ab"}),
        "text id": (frame, {"a": [(0, 0), (3, 3)]}),
    }
    refused["read-only"][0].flags.writeable = False
    for case, (f, t) in refused.items():
        before = frame.copy()
        with pytest.raises((TypeError, ValueError)) as info:
            render.draw_trails(f, t)
        message = str(info.value)
        assert message.startswith("draw_trails: ") and "\n" not in message, (case, message)
        np.testing.assert_array_equal(frame, before)  # nothing drawn before the refusal
    for shape, kind in (((-1, 5), ValueError), ((2.0, 5), TypeError), (frame, TypeError)):
        with pytest.raises(kind, match="^ink_scale: shape "):
            render.ink_scale(shape)


@pytest.mark.parametrize("fn", [np.zeros((3, 4)), None, 5, b"detect"], ids=str)
@pytest.mark.parametrize("frame", [_FRAME, None, np.zeros((6, 8, 3))], ids=["good", "None", "f8"])
def test_check_frame_names_its_own_fn_in_one_line(fn: object, frame: object) -> None:
    """``check_frame(frame, fn=array)``: the array's repr began the message, over several lines
    (a good frame passed, so a wrong `fn` showed only at a bad frame)."""
    with pytest.raises(TypeError) as info:
        check_frame(frame, fn)  # type: ignore[arg-type]
    assert str(info.value).startswith("check_frame: fn must be a str") and "\n" not in str(
        info.value
    )
    assert check_frame(_FRAME, "PaperDetector.detect") is _FRAME  # the same array, as before
