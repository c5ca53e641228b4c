"""Annotated video: drawn while tracking, on a worker thread, with trails."""

from __future__ import annotations

import ast
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from pftrack.io.opencv_io import text_for_opencv
from pftrack.render import TrackRenderer, colour_of, plot_trajectories, write_annotated_video
from tests.io.decode import decode


@dataclass(frozen=True)
class FakeTrack:
    id: int
    box_xywh: np.ndarray
    time_since_update: int = 0


def _walk(n: int) -> list[list[FakeTrack]]:
    """One object walking right, 4 px a frame, from (10, 20)."""
    return [[FakeTrack(5, np.array([10.0 + 4 * k, 20.0, 12.0, 30.0]))] for k in range(n)]


def _render(path: Path, threaded: bool, n: int = 20) -> Path:
    renderer = TrackRenderer(path, 7, threaded=threaded, trail=40)
    for tracks in _walk(n):
        renderer.add(np.full((80, 120, 3), 40, np.uint8), tracks)
    return renderer.close()


def test_threaded_rendering_equals_drawing_in_line(tmp_path: Path) -> None:
    a = _render(tmp_path / "a.mp4", threaded=True)
    b = _render(tmp_path / "b.mp4", threaded=False)
    stream, fa = decode(a)
    _, fb = decode(b)
    assert (stream.codec, stream.pix_fmt) == ("h264", "yuv420p")
    assert stream.average_rate == 7 and len(fa) == len(fb) == 20
    for x, y in zip(fa, fb, strict=True):
        np.testing.assert_array_equal(x, y)


def test_the_trail_follows_the_foot_points(tmp_path: Path) -> None:
    _, frames = decode(_render(tmp_path / "a.mp4", threaded=True))
    last = frames[-1].astype(int)
    colour = np.array(colour_of(5))
    # foot points run along y = 50 from x = 16 to 16 + 4 * 19 = 92; the box (x >= 86) aside,
    # the trail is there on the last frame and was not on the first
    row = last[50, 20:80]
    assert np.abs(row - colour).sum(axis=1).max() < 120
    assert np.abs(frames[0][50, 30:80].astype(int) - 40).max() < 10  # the first box ends at 22


def test_a_worker_error_surfaces_and_leaves_no_file(tmp_path: Path) -> None:
    renderer = TrackRenderer(tmp_path / "a.mp4", 7)
    renderer.add(np.zeros((40, 60, 3), np.uint8), [])
    renderer.add(np.zeros((30, 60, 3), np.uint8), [])  # another size: the encoder refuses it
    with pytest.raises(ValueError, match="the video 60x40"):
        renderer.close()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("threaded", [True, False])
@pytest.mark.parametrize("end", ["close", "abort"])
def test_a_frame_after_the_end_is_refused_not_queued(
    tmp_path: Path, threaded: bool, end: str
) -> None:
    """Was: queued silently for the stopped worker, and the 9th ``add`` waited for ever."""
    renderer = TrackRenderer(tmp_path / "a.mp4", 7, threaded=threaded)
    frame = np.zeros((40, 60, 3), np.uint8)
    renderer.add(frame, [])
    getattr(renderer, end)()
    state = "closed" if end == "close" else "aborted"
    for _ in range(10):  # more than the queue holds
        with pytest.raises(ValueError, match=rf"^TrackRenderer.add: .*a.mp4 is {state} already"):
            renderer.add(frame, [])
    assert renderer.n_frames == 1
    assert [p.name for p in tmp_path.iterdir()] == (["a.mp4"] if end == "close" else [])


def test_a_ctrl_c_in_abort_waits_for_the_worker_then_is_raised(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Was: the wait cut short, the worker left drawing inside OpenCV as the process exited."""
    renderer = TrackRenderer(tmp_path / "a.mp4", 7)
    drawing, drawn = threading.Event(), threading.Event()
    draw = renderer._draw

    def slow(job: Any) -> None:
        drawing.set()
        time.sleep(0.6)
        draw(job)
        drawn.set()

    monkeypatch.setattr(renderer, "_draw", slow)
    renderer.add(np.zeros((40, 60, 3), np.uint8), [])
    assert drawing.wait(timeout=10)
    main = threading.main_thread().ident
    assert main is not None
    timer = threading.Timer(0.2, signal.pthread_kill, (main, signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        renderer.abort()
    timer.join()
    assert drawn.is_set()
    assert not [t for t in threading.enumerate() if t.name == "pftrack-render" and t.is_alive()]
    assert list(tmp_path.iterdir()) == []


def test_write_annotated_video_from_rows(tmp_path: Path) -> None:
    rows = np.array([[k, 3, 10 + 2 * k, 10, 8, 16, 1, -1, -1, -1] for k in range(1, 11)], float)
    frames = [np.zeros((48, 64, 3), np.uint8) for _ in range(10)]
    stream, got = decode(write_annotated_video(tmp_path / "v.mp4", frames, rows, fps=12.5))
    assert stream.average_rate == 12.5 and len(got) == 10
    # foot points along y = 26 from x = 16 to 34; the last box spans x 30..38
    assert got[-1][26, 17:28].max(axis=1).min() > 100
    assert got[0][26, 22:28].max() < 30


def test_a_trail_holds_only_the_foot_points_of_the_last_trail_frames(tmp_path: Path) -> None:
    # id 3 at frames 1-5 (feet at x 14..22), away, then back at frames 56-60 (feet at x 84):
    # was a trail line from frame 5's foot, 51 frames old, across x 22..84 on frame 56
    rows = np.array(
        [[k, 3, 10 + 2 * (k - 1), 10, 8, 16, 1, -1, -1, -1] for k in range(1, 6)]
        + [[k, 3, 80, 10, 8, 16, 1, -1, -1, -1] for k in range(56, 61)],
        float,
    )
    frames = [np.zeros((48, 120, 3), np.uint8) for _ in range(60)]
    _, got = decode(write_annotated_video(tmp_path / "v.mp4", frames, rows, fps=10, trail=40))
    assert got[4][26, 15:21].max(axis=1).min() > 100  # the trail of frames 1-5 is drawn
    assert got[55][26, 30:75].max() < 30


def test_labels_grow_with_the_frame() -> None:
    """Was: 0.4-scale labels and 1-2 px lines at any size, about 10 px tall at 1920x1080."""
    from pftrack.render import draw_tracks, ink_scale

    assert [ink_scale(s) for s in [(360, 480), (720, 1280), (1080, 1920), (2160, 3840)]] == [
        1,
        1,
        2,
        4,
    ]
    row = np.array([[1, 7, 100, 100, 60, 150, 1, -1, -1, -1]], float)
    inked = []
    for size in [(360, 480), (1080, 1920)]:
        out = draw_tracks(np.zeros((*size, 3), np.uint8), row)
        inked.append(int(np.count_nonzero(out.any(axis=2))))
    assert inked[1] > 1.5 * inked[0]  # twice the line width, and a twice larger label


_ROWS = np.array([[k, i, 10 + 20 * k, 30 * i, 10, 20, 1, -1, -1, -1]
                  for k in range(1, 6) for i in (1, 2)], float)  # fmt: skip


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda p: plot_trajectories(p, _ROWS[:, :5]),
         r"plot_trajectories: rows has shape \(10, 5\), expected \(M, 6\+\) MOT rows: frame, id, "
         r"left, top, width, height\[, \.\.\.\]$"),
        (lambda p: plot_trajectories(p, _ROWS, truth=_ROWS[:, 0]),
         r"plot_trajectories: truth has shape \(10,\), expected \(M, 6\+\) MOT rows: frame"),
        (lambda p: plot_trajectories(p, np.where(_ROWS == 50, np.nan, _ROWS)),
         r"plot_trajectories: rows row 2 has NaN or inf in frame, id, left, top, width, height$"),
        (lambda p: plot_trajectories(p, _ROWS, size=(0, 10)),
         r"plot_trajectories: size is \(0, 10\), expected \(width, height\), whole numbers"),
        (lambda p: plot_trajectories(p, _ROWS * [1, 1, 1e6, 1, 1, 1, 1, 1, 1, 1]),
         r"plot_trajectories: the boxes reach .* beyond 32767 px a side; give a background"),
        (lambda p: write_annotated_video(p, [np.zeros((8, 8, 3), np.uint8)], _ROWS[:, :5], 25),
         r"write_annotated_video: rows has shape \(10, 5\), expected \(M, 6\+\) MOT rows"),
        (lambda p: write_annotated_video(p, [], _ROWS, 25),
         r"write_annotated_video: frames is empty; no frame to write$"),
        (lambda p: write_annotated_video(p, iter(()), _ROWS, 25),
         r"write_annotated_video: frames is empty; no frame to write$"),
    ],
)  # fmt: skip
def test_pictures_refuse_bad_arguments_in_one_line(tmp_path: Path, call: Any, message: str) -> None:
    """Was: a raw IndexError (5 columns), and OSError "nothing was written" (no frame)."""
    with pytest.raises(ValueError, match=message):
        call(tmp_path / "out.png")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("frames", [None, 3, np.array(3)], ids=repr)
def test_frames_that_are_not_an_iterable_are_named(tmp_path: Path, frames: object) -> None:
    """Was: 'NoneType' object is not iterable (iteration over a 0-d array), naming nothing."""
    with pytest.raises(TypeError, match=r"^write_annotated_video: frames must be an iterable of "
                       r"\(H, W, 3\) uint8 frames, got (NoneType|int|ndarray)"):  # fmt: skip
        write_annotated_video(tmp_path / "v.mp4", frames, _ROWS, 25)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []


def test_a_plot_without_background_has_axes_in_image_coordinates(tmp_path: Path) -> None:
    """Was: a canvas of the boxes' extent and no axis: coordinates could not be read."""
    import cv2

    path = plot_trajectories(tmp_path / "p.png", _ROWS, title="two walkers")
    image = cv2.imread(str(path))
    w, h = int((_ROWS[:, 2] + _ROWS[:, 4]).max()) + 10, int((_ROWS[:, 3] + _ROWS[:, 5]).max()) + 10
    assert image.shape[0] > h and image.shape[1] > w  # margins for the labels
    grey = (image == 170).all(axis=2)
    # the frame: one grey column (left edge) and one grey row (bottom edge) as long as the canvas
    assert grey.sum(axis=0).max() >= h and grey.sum(axis=1).max() >= w
    # track 2's path: y = 60 + 20 (its foot) is drawn below track 1's (y = 30 + 20): y down
    ys = {tid: np.flatnonzero((image == colour_of(tid)).all(axis=2).any(axis=1)) for tid in (1, 2)}
    assert ys[2].mean() > ys[1].mean()
    # with a background: the background's size, no margins
    bg = np.full((120, 200, 3), 80, np.uint8)
    framed = cv2.imread(str(plot_trajectories(tmp_path / "b.png", _ROWS, background=bg)))
    assert framed.shape == (120, 200, 3)


def test_text_for_opencv_is_printable_ascii() -> None:
    assert text_for_opencv("frame 12") == "frame 12"
    assert text_for_opencv(os.fsdecode(b"v\xe9deo.mp4")) == "v\\xe9deo.mp4"  # not UTF-8
    assert text_for_opencv("vid\udcc3\udca9o") == "video"  # UTF-8 bytes, escaped (C locale)
    assert text_for_opencv("vidéo 東京\n\t\x00\ud800") == "video ?????\\ud800"
    assert all(" " <= c <= "~" for c in text_for_opencv("".join(map(chr, range(0x3000)))))


def test_a_title_that_is_not_utf8_is_drawn(tmp_path: Path) -> None:
    """Was: a segmentation fault in ``cv2.putText`` (``pftrack track --plot`` on a Latin-1 file
    name); run in a subprocess, where a crash is an exit status, not the end of the tests."""
    code = textwrap.dedent(
        """
        import os, sys
        import numpy as np
        from pftrack.render import draw_tracks, plot_trajectories
        rows = np.array([[k, 3, 10 + 2 * k, 10, 8, 16, 1, -1, -1, -1] for k in (1, 2)], float)
        name = os.fsdecode(b"v\\xe9deo.mp4")
        plot_trajectories(sys.argv[1], rows, size=(64, 48), title=name)
        draw_tracks(np.zeros((48, 64, 3), np.uint8), rows[:1], label=name)
        """
    )
    out = tmp_path / "p.png"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    run = subprocess.run([sys.executable, "-c", code, str(out)], env=env, capture_output=True,
                         timeout=60, check=False)  # fmt: skip
    assert run.returncode == 0, (run.returncode, run.stderr)
    assert out.stat().st_size > 0


def test_every_text_the_package_draws_goes_through_text_for_opencv() -> None:
    """``cv2.putText`` crashes on some ``str`` (:func:`text_for_opencv`): none reaches it raw."""
    package = Path(__file__).resolve().parents[1] / "python" / "pftrack"
    raw, calls = [], 0
    for path in sorted(package.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and (node.func.attr == "putText")
            ):
                calls += 1
                text = node.args[1] if len(node.args) > 1 else None
                if not (
                    isinstance(text, ast.Call)
                    and isinstance(text.func, ast.Name)
                    and text.func.id == "text_for_opencv"
                ):
                    raw.append(f"{path.relative_to(package)}:{node.lineno}")
    assert calls >= 4 and raw == []


@pytest.mark.parametrize(
    ("trail", "error", "message"),
    [
        (-1, ValueError, "trail is -1, expected an integer in [0, 100000]"),
        (10**30, ValueError, "trail is 1000000000000000000000000000000, expected an integer in"),
        (2.5, TypeError, "trail must be an integer in [0, 100000], got float 2.5"),
        ("40", TypeError, "trail must be an integer in [0, 100000], got str '40'"),
        (None, TypeError, "trail must be an integer in [0, 100000], got NoneType None"),
        (True, TypeError, "trail must be an integer in [0, 100000], got bool True"),
    ],
)
def test_a_bad_trail_is_refused_alike_by_both_writers(
    trail: object, error: type[Exception], message: str, tmp_path: Path
) -> None:
    """Was: write_annotated_video drew no trail for -1 (TrackRenderer refused it), and both
    said "'>' not supported between instances of 'int' and 'str'", "an integer is required" or
    an OverflowError, or took 2.5 and True as 2 and 1."""
    rows = np.array([[1, 1, 10, 10, 20, 40], [2, 1, 12, 10, 20, 40]], float)
    frames = [np.zeros((48, 64, 3), np.uint8)] * 2
    with pytest.raises(error) as info:
        write_annotated_video(tmp_path / "v.mp4", frames, rows, trail=trail)  # type: ignore[arg-type]
    assert str(info.value).startswith(message)
    with pytest.raises(error) as info:
        TrackRenderer(tmp_path / "w.mp4", 10, trail=trail)  # type: ignore[arg-type]
    assert str(info.value).startswith(message)
    assert sorted(os.listdir(tmp_path)) == []  # no file, no temporary file


def test_the_pictures_refuse_what_they_cannot_draw_in_one_line(tmp_path: Path) -> None:
    """Was: ``plot_trajectories(title=123)`` an AttributeError ('int' object has no attribute
    'encode'), ``draw_tracks`` of (k, 5) rows "not enough values to unpack (expected 4, got
    3)", ``TrackRenderer(queue_size='8')`` "'>' not supported between 'int' and 'str'"."""
    from pftrack.render import draw_tracks

    rows = np.array([[1, 1, 10, 10, 20, 40], [2, 1, 12, 10, 20, 40]], float)
    frame = np.zeros((48, 64, 3), np.uint8)
    with pytest.raises(TypeError, match=r"^plot_trajectories: title must be a str, got int 123$"):
        plot_trajectories(tmp_path / "p.png", rows, title=123)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match=r"^draw_tracks: label must be a str, got int 7$"):
        draw_tracks(frame, rows[:1], label=7)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^draw_tracks: rows has shape \(1, 5\), expected \(M"):
        draw_tracks(frame, np.ones((1, 5)))
    with pytest.raises(TypeError, match=r"^queue_size must be an integer in \[0, "):
        TrackRenderer(tmp_path / "v.mp4", 10, queue_size="8")  # type: ignore[arg-type]
    assert sorted(os.listdir(tmp_path)) == []
    assert draw_tracks(frame, rows[:1], label="frame 1").shape == frame.shape  # still drawn
    assert draw_tracks(frame, np.zeros((0, 8))).shape == frame.shape


def test_a_filled_box_is_dashed_and_a_ground_truth_class_is_not_a_fill() -> None:
    """Was: any row whose column 8 is 1 drawn thin (said: dashed), MOT16+ truth's class 1 too."""
    from pftrack.render import draw_tracks

    frame = np.zeros((80, 100, 3), np.uint8)

    def top_edge(extra: list[float]) -> np.ndarray:
        row = np.array([[1, 4, 20, 30, 60, 40, *extra]], float)
        return draw_tracks(frame, row)[30, 22:78].max(axis=1)  # the box's top edge, corners out

    observed = top_edge([])  # a 6-column row: observed
    assert observed.min() > 100  # solid
    filled = top_edge([1, 1, -1, -1])  # pftrack's interpolated flag (filled_mask)
    assert filled.max() > 100 and (filled < 30).sum() >= 10  # dashes and gaps
    for truth in ([1, 1, 0.5, -1], [1, 1, -1, 0.8], [1, 1]):  # MOT16+ truth: class 1, visibility
        np.testing.assert_array_equal(top_edge(truth), observed)


@pytest.mark.parametrize("left", [-30.0, 90.0, 40.0])
def test_an_id_is_drawn_whole_inside_the_frame_when_its_box_is_not(left: float) -> None:
    """Was: the label at the box's left edge, off the frame for a box entering from the left."""
    from pftrack.render import draw_tracks

    frame = np.zeros((80, 120, 3), np.uint8)
    row = np.array([[1, 123456, left, 40, 50, 30]], float)
    label = draw_tracks(frame, row)[:36].any(axis=2)  # above the box: the label alone
    centred = draw_tracks(frame, row * [1, 1, 0, 1, 1, 1] + [0, 0, 30, 0, 0, 0])[:36].any(axis=2)
    assert label.sum() == centred.sum() > 50  # all of it, as of a box in the middle


@pytest.mark.parametrize("tid", [7, 8, 123456])
def test_ids_and_the_frame_number_are_legible_on_any_frame(tid: int) -> None:
    """Was: white frame numbers on a white frame, an id in its colour on that colour, unseen."""
    from pftrack.render import draw_tracks

    row = np.array([[1, tid, 40, 40, 50, 30]], float)
    for fill in [(255, 255, 255), colour_of(tid), (0, 0, 0)]:
        frame = np.full((80, 120, 3), fill, np.uint8)
        out = draw_tracks(frame, row, "frame 1").astype(int)
        for where in (out[:20, :60], out[22:38, 30:110]):  # the frame number; the id over its box
            # the text stands out of what is drawn around it: a dark and a light shade both
            luma = where @ [0.114, 0.587, 0.299]
            assert luma.max() - luma.min() > 100, (fill, where.shape)


def test_paths_title_counts_the_tracks_and_frames() -> None:
    from pftrack.render import paths_title

    assert paths_title("s", _ROWS) == "s: foot-point paths of 2 tracks, frames 1-5"
    assert paths_title("s", _ROWS[:1]) == "s: foot-point paths of 1 track, frame 1"
    assert paths_title("s", []) == "s: foot-point paths of 0 tracks"


@pytest.mark.parametrize("start", [-40.0, 15.0, 190.0])
def test_a_plot_labels_each_path_legibly_inside_the_canvas(tmp_path: Path, start: float) -> None:
    """Was: the id in its colour at the path's first point: off the canvas for a track that
    came in from outside, dim for a blue one on a dark frame."""
    import cv2

    tid = min(range(1, 50), key=lambda i: sum(np.array(colour_of(i)) * [0.114, 0.587, 0.299]))
    rows = np.array([[k, tid, start + 10 * k, 10, 10, 30, 1, -1, -1, -1] for k in range(8)], float)
    dark = np.zeros((80, 200, 3), np.uint8)
    image = cv2.imread(str(plot_trajectories(tmp_path / "p.png", rows[::-1], background=dark)))
    luma = image.astype(int) @ [0.114, 0.587, 0.299]
    near = luma[20:45, max(0, int(start) - 5) : int(start) + 45]  # about where the path starts
    assert near.max() > 200  # white ink on the id's tag
    assert (luma > 200).sum() > 10


def test_a_trail_is_not_drawn_across_frames_its_track_is_absent(tmp_path: Path) -> None:
    """Was: a straight line from where a track was last seen to where it came back, as if walked
    (a track that left the frame and re-entered within `trail` frames, or a hole in a file)."""
    rows = np.array(
        [[k, 3, 10 + 2 * (k - 1), 10, 8, 16, 1, -1, -1, -1] for k in range(1, 6)]
        + [[k, 3, 80 + 2 * (k - 10), 10, 8, 16, 1, -1, -1, -1] for k in range(10, 15)],
        float,
    )
    frames = [np.zeros((48, 120, 3), np.uint8) for _ in range(14)]
    _, got = decode(write_annotated_video(tmp_path / "v.mp4", frames, rows, fps=10, trail=40))
    assert got[4][26, 15:21].max(axis=1).min() > 100  # frames 1-5: their trail
    assert got[13][26, 85:92].max(axis=1).min() > 100  # frames 10-14: theirs
    assert got[13][26, 30:75].max() < 30  # nothing between them


@pytest.mark.parametrize("filled", [False, True])
def test_a_plot_draws_a_hole_in_a_track_thin(tmp_path: Path, filled: bool) -> None:
    """Was: a hole (frames 6-9 missing, or filled) drawn as the observed path is, 2 px wide."""
    import cv2

    rows = np.array(
        [[k, 3, 10 + 2 * (k - 1), 10, 8, 16, 1, -1, -1, -1] for k in range(1, 6)]
        + [[k, 3, 80 + 2 * (k - 10), 10, 8, 16, 1, -1, -1, -1] for k in range(10, 15)]
        + [[k, 3, 18 + 16 * (k - 5), 10, 8, 16, 1, 1, -1, -1] for k in range(6, 10) if filled],
        float,
    )
    dark = np.zeros((48, 120, 3), np.uint8)
    image = cv2.imread(str(plot_trajectories(tmp_path / "p.png", rows, background=dark)))
    lit = image.max(axis=2) > 60
    assert lit[:, 45].sum() == 1 and lit[:, 90].sum() >= 2  # the hole 1 px, the path 2 or more


def test_a_frame_too_small_for_its_number_is_not_covered_by_it() -> None:
    """Was: on a 32x24 frame the frame number's tag hid two thirds of the picture."""
    from pftrack.render import draw_tracks

    for size in [(24, 32), (60, 100)]:
        frame = np.full((*size, 3), 90, np.uint8)
        changed = (draw_tracks(frame, np.zeros((0, 6)), "frame 123") != 90).any(axis=2)
        assert changed.mean() < 0.25, size
    shown = draw_tracks(np.full((120, 160, 3), 90, np.uint8), np.zeros((0, 6)), "frame 123")
    assert (shown != 90).any(axis=2).mean() > 0.02  # drawn where it fits


def test_a_coasting_track_is_dashed_while_tracking(tmp_path: Path) -> None:
    renderer = TrackRenderer(tmp_path / "a.mp4", 7, threaded=False)
    seen = FakeTrack(1, np.array([10.0, 20.0, 60.0, 30.0]))
    coasting = FakeTrack(2, np.array([10.0, 60.0, 60.0, 30.0]), time_since_update=3)
    renderer.add(np.zeros((100, 120, 3), np.uint8), [seen, coasting])
    _, [frame] = decode(renderer.close())
    solid, dashed = frame[20, 14:66].max(axis=1), frame[60, 14:66].max(axis=1)
    assert solid.min() > 100 and dashed.max() > 100 and (dashed < 40).sum() >= 10


@pytest.mark.parametrize(
    ("frame", "error", "message"),
    [
        (None, TypeError, r"frame is NoneType, expected a \(H, W, 3\) uint8 BGR array$"),
        (np.full((48, 64, 3), 0.8), TypeError, r"frame dtype is float64, expected uint8"),
        (np.zeros((48, 64), np.uint8), ValueError, r"frame must have shape \(H, W, 3\)"),
    ],
    ids=["none", "float", "grey"],
)
def test_the_video_pictures_refuse_a_frame_that_is_not_bgr_uint8(
    tmp_path: Path, frame: object, error: type[Exception], message: str
) -> None:
    """In the caller's thread, naming the call. Was: a float frame drawn black without a word
    (TrackRenderer) or OpenCV's assertion in putText (write_annotated_video, draw_tracks),
    None an AttributeError ('NoneType' object has no attribute 'copy')."""
    from pftrack.render import draw_tracks

    rows = np.array([[1, 1, 10, 10, 20, 40]], float)
    with pytest.raises(error, match=r"^write_annotated_video: " + message):
        write_annotated_video(tmp_path / "v.mp4", [frame], rows)  # type: ignore[list-item]
    renderer = TrackRenderer(tmp_path / "w.mp4", 10)
    with pytest.raises(error, match=r"^TrackRenderer.add: " + message):
        renderer.add(frame, _walk(1)[0])  # type: ignore[arg-type]
    renderer.abort()
    with pytest.raises(error, match=r"^draw_tracks: " + message):
        draw_tracks(frame, rows, "frame 1")  # type: ignore[arg-type]
    assert sorted(os.listdir(tmp_path)) == []


def test_track_renderer_refuses_what_is_not_a_track_in_one_line(tmp_path: Path) -> None:
    """``renderer.add(frame, tracker.update(dets, frame))`` with the drop-in Tracker's (M, 8)
    rows instead of MultiObjectTracker's Track objects. Was: AttributeError 'numpy.ndarray'
    object has no attribute 'box_xywh'."""
    frame = np.zeros((48, 64, 3), np.uint8)
    renderer = TrackRenderer(tmp_path / "v.mp4", 10)
    rows = np.array([[10.0, 10.0, 30.0, 50.0, 1, 0.9, 0, 0]])  # Tracker.update's x1..y2, id, ...
    for tracks in (rows, [None], "abc"):
        with pytest.raises(
            TypeError,
            match=r"^TrackRenderer.add: tracks\[0\] is (ndarray|NoneT"
            r"ype|str), expected a track with id, box_xywh and time_since_update",
        ):
            renderer.add(frame, tracks)  # type: ignore[arg-type]
    renderer.add(frame, _walk(1)[0])  # the renderer goes on
    assert renderer.close() == tmp_path / "v.mp4"


@pytest.mark.parametrize("tracks", [None, 3], ids=repr)
def test_renderer_add_names_tracks_that_are_not_iterable(tmp_path: Path, tracks: object) -> None:
    """Was: 'NoneType' object is not iterable (an update's result that was None)."""
    renderer = TrackRenderer(tmp_path / "v.avi", 10.0, threaded=False)
    frame = np.zeros((16, 16, 3), np.uint8)
    message = (
        r"^TrackRenderer\.add: tracks must be an iterable of tracks "
        r"\(MultiObjectTracker\.update's list\), got (NoneType|int)$"
    )
    with pytest.raises(TypeError, match=message):
        renderer.add(frame, tracks)  # type: ignore[arg-type]
    renderer.add(frame, [])  # the renderer goes on
    renderer.close()
    assert (tmp_path / "v.avi").is_file()


def test_a_lost_wake_up_of_the_worker_is_found(tmp_path: Path) -> None:
    """A Ctrl-C between ``Queue.put``'s append and its notify (or one that broke the queue's
    lock) leaves an item queued and the worker asleep: ``pftrack track --render`` hung on
    Ctrl-C in ``abort()``'s join (was: the worker slept in ``get()`` for ever)."""
    import time

    r = TrackRenderer(tmp_path / "a.avi", 10.0)
    r.add(np.zeros((48, 64, 3), np.uint8), [])
    time.sleep(0.3)  # the worker has drawn it and waits for the next
    q, worker = r._queue, r._thread
    assert q is not None and worker is not None
    with q.mutex:
        q.queue.append(None)  # queued, no one woken
    worker.join(5.0)
    alive = worker.is_alive()
    if alive:  # the old worker: wake it, so that the test ends
        q.put(None)
    r.abort()
    assert not alive


def test_the_caller_never_sleeps_on_the_queues_condition(tmp_path: Path) -> None:
    """``add`` on a full queue waits for room in short sleeps, not in ``Condition.wait``: a
    Ctrl-C that lands there as it takes the queue's lock back leaves the lock released under
    the worker (the hang above; was ``Queue.put``, blocking)."""
    import threading

    r = TrackRenderer(tmp_path / "a.avi", 10.0, queue_size=1)
    q = r._queue
    assert q is not None
    go = threading.Event()
    draw = r._draw

    def slow(job: Any) -> None:
        go.wait(5.0)
        draw(job)

    waits: list[str] = []
    condition_wait = q.not_full.wait

    def wait(timeout: float | None = None) -> bool:
        waits.append(threading.current_thread().name)
        return condition_wait(timeout)

    r._draw = slow  # type: ignore[method-assign]
    q.not_full.wait = wait  # type: ignore[method-assign]
    threading.Timer(0.5, go.set).start()
    for _ in range(4):
        r.add(np.zeros((48, 64, 3), np.uint8), [])
    r.close()
    assert r.n_frames == 4 and waits == []


def test_a_long_title_is_wrapped_on_a_narrow_frame(tmp_path: Path) -> None:
    """A CLI trial: the title of a 3000-frame video's plot on its 320x240 frame ran past the
    right edge ("... frames 1-300", the last digit cut off); it takes two lines now."""
    title = "long.avi: foot-point paths of 33 tracks, frames 1-3000"
    rows = np.array(
        [[1, 1, 100, 100, 20, 40, 1, -1, -1, -1], [2, 1, 104, 100, 20, 40, 1, -1, -1, -1]]
    )

    def title_ink(width: int) -> np.ndarray:
        """(row, column) of the white title's pixels on a black frame `width` wide."""
        black = np.zeros((240, width, 3), np.uint8)
        path = plot_trajectories(tmp_path / f"{width}.png", rows, black, title=title)
        return np.argwhere(cv2.imread(str(path))[:40].max(axis=2) > 150)  # the paths lie below

    ink = title_ink(320)
    assert ink[:, 1].max() <= 320 - 5  # inside the frame, with its margin
    assert ink[:, 0].max() > 20  # on a second line
    assert title_ink(640)[:, 0].max() <= 20  # one line where the frame is wide enough


def _tags_drawn(monkeypatch: pytest.MonkeyPatch) -> list[tuple[int, int, int, int]]:
    """The boxes of the id tags ``pftrack.render`` draws from now on, in order."""
    import pftrack.render as render

    boxes: list[tuple[int, int, int, int]] = []
    tag = render._tag

    def spy(*args: Any, **kwargs: Any) -> tuple[int, int, int, int]:
        box = tag(*args, **kwargs)
        boxes.append(box)
        return box

    monkeypatch.setattr(render, "_tag", spy)
    return boxes


def _assert_apart_inside(boxes: list[tuple[int, int, int, int]], width: int, height: int) -> None:
    """Every tag whole inside a `width` x `height` picture, and none touching another."""
    for i, a in enumerate(boxes):
        assert 0 <= a[0] <= a[2] < width and 0 <= a[1] <= a[3] < height, a
        for b in boxes[:i]:
            apart = a[2] < b[0] or b[2] < a[0] or a[3] < b[1] or b[3] < a[1]
            assert apart, (a, b)


@pytest.mark.parametrize("background", [False, True])
def test_plot_ids_of_paths_that_begin_or_end_together_do_not_overlap(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, background: bool
) -> None:
    """Was (trial61): ids drawn on top of one another at the plot's right edge, where people
    walk in together. Three tracks from one spot past the right edge to one spot in the middle:
    their id tags (and those of three more from one spot mid-plot) are moved apart, inside it."""

    boxes = _tags_drawn(monkeypatch)
    rows = np.array(
        [[f, tid, left, 40.0 + 2 * f, 20.0, 40.0] for tid in (1, 2, 3, 104, 105, 106)
         for f, left in ((1, 195.0 if tid < 100 else 80.0), (2, 90.0))],
    )  # fmt: skip
    if background:
        plot_trajectories(tmp_path / "p.png", rows, np.full((150, 200, 3), 90, np.uint8))
    else:
        plot_trajectories(tmp_path / "p.png", rows, size=(200, 150))
    assert len(boxes) == 6
    _assert_apart_inside(boxes, 200, 150)


def test_video_ids_of_people_side_by_side_do_not_overlap(monkeypatch: pytest.MonkeyPatch) -> None:
    """Was (issue 17): ``--render``'s id tags drawn over one another for people walking side by
    side, and over the frame number in the corner. Four boxes whose tags would share one place
    and one under the frame number: every tag is moved apart the least, inside the frame, and
    the frame number stays in its corner."""
    import pftrack.render as render

    boxes = _tags_drawn(monkeypatch)
    rows = np.array(
        [[1, tid, left, 60.0 if tid < 15 else 24.0, 30.0, 60.0, 1, -1, -1, -1]
         for tid, left in ((11, 100.0), (12, 104.0), (13, 96.0), (14, 102.0), (15, 8.0))]
    )  # fmt: skip
    alone = render.draw_tracks(np.zeros((160, 240, 3), np.uint8), rows[:1], "frame 1")
    first = boxes[:]
    boxes.clear()
    out = render.draw_tracks(np.zeros((160, 240, 3), np.uint8), rows, "frame 1")
    assert len(boxes) == 6 and boxes[0] == first[0] and boxes[-1] == first[-1]
    _assert_apart_inside(boxes, 240, 160)
    # the frame number where it was, over the boxes; the first id too, the others each within
    # a few tags' heights of where it was asked
    np.testing.assert_array_equal(out[: first[-1][3] + 1, :60], alone[: first[-1][3] + 1, :60])
    height = boxes[0][3] - boxes[0][1] + 1
    assert all(abs(b[1] - boxes[0][1]) <= 3 * height for b in boxes[1:4]), boxes
    assert boxes[4][1] > first[-1][3], boxes  # id 15 just under the frame number


@pytest.mark.parametrize("threaded", [False, True])
def test_a_track_with_a_nan_box_is_named_by_add_itself(tmp_path: Path, threaded: bool) -> None:
    """The worker draws rows ``add`` checked (not checked again each frame): a NaN box is a
    ValueError of ``add`` naming the tracks, in the caller's thread, and no file is left."""
    renderer = TrackRenderer(tmp_path / "v.mp4", 7, threaded=threaded)
    renderer.add(np.zeros((40, 60, 3), np.uint8), _walk(1)[0])
    bad = [FakeTrack(5, np.array([10.0, np.nan, 12.0, 30.0]))]
    with pytest.raises(ValueError, match=r"^TrackRenderer.add: tracks row 0 has NaN or inf in "):
        renderer.add(np.zeros((40, 60, 3), np.uint8), bad)
    renderer.abort()
    assert not (tmp_path / "v.mp4").exists()


def _free_y_searching_all(
    taken: list[tuple[int, int, int, int]],
    x0: int,
    x1: int,
    y: int,
    above: int,
    below: int,
    rows: int,
) -> int:
    """render._free_y as it was before stop 65: every try sorted by its distance from `y`."""

    def free(b: int) -> bool:
        return all(x1 < t[0] or t[2] < x0 or b + below < t[1] or t[3] < b - above for t in taken)

    inside = range(above, rows - below)
    tries = [y] + [t[3] + above + 1 for t in taken] + [t[1] - below - 1 for t in taken]
    return next((b for b in sorted(tries, key=lambda b: abs(b - y)) if b in inside and free(b)), y)


def test_a_tag_moves_where_the_search_of_every_try_puts_it() -> None:
    # a crowd's tags: 60 a frame, many on one another and at the frame's edges, so that the
    # shortcut (the asked baseline itself, when free and inside) and the sorted search both act
    from pftrack.render import _free_y

    rng = np.random.default_rng(65)
    shortcut = moved = 0
    for _ in range(300):
        rows = int(rng.integers(40, 200))
        taken: list[tuple[int, int, int, int]] = []
        for _ in range(int(rng.integers(0, 60))):
            x0 = int(rng.integers(-20, 300))
            y0 = int(rng.integers(-20, rows + 20))
            taken.append((x0, y0, x0 + int(rng.integers(5, 40)), y0 + int(rng.integers(5, 20))))
        for _ in range(5):
            x0 = int(rng.integers(-20, 300))
            x1 = x0 + int(rng.integers(5, 40))
            y = int(rng.integers(-20, rows + 20))
            above, below = int(rng.integers(5, 15)), int(rng.integers(0, 6))
            want = _free_y_searching_all(taken, x0, x1, y, above, below, rows)
            assert _free_y(taken, x0, x1, y, above, below, rows) == want
            shortcut += want == y
            moved += want != y
    assert shortcut > 100 and moved > 100  # both ways were taken
