"""``pftrack render``: a tracks file drawn on its video, as the library's writer draws it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot, write_mot
from pftrack.io.video import FrameSource
from pftrack.io.video_writer import VideoWriter
from pftrack.render import write_annotated_video
from pftrack.synthetic import Scene, make_scene
from tests.io.decode import decode


@pytest.fixture(scope="module")
def scene_files(tmp_path_factory: pytest.TempPathFactory) -> tuple[Scene, Path, Path]:
    folder = tmp_path_factory.mktemp("render")
    scene = make_scene(n_frames=30, n_walkers=3, rng=0)
    video = scene.write_video(folder / "scene.avi")
    truth = folder / "truth.txt"
    write_mot(truth, scene.truth)
    return scene, video, truth


def test_the_file_is_drawn_as_write_annotated_video_draws_it(
    scene_files: tuple[Scene, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, video, truth = scene_files
    out, plot = tmp_path / "drawn.mp4", tmp_path / "paths.png"
    assert main(["render", str(video), str(truth), "--out", str(out), "--plot", str(plot),
                 "--fps", "12"]) == 0  # fmt: skip
    said = capsys.readouterr().out
    assert f"30 frames, 3 tracks, {len(read_mot(truth))} boxes drawn, 12 fps (--fps)" in said
    ref = write_annotated_video(tmp_path / "ref.mp4", FrameSource(video), read_mot(truth), 12.0)
    info, frames = decode(out)
    _, expected = decode(ref)
    assert info.codec == "h264" and len(frames) == 30
    assert all(np.array_equal(a, b) for a, b in zip(frames, expected, strict=True))
    assert not np.array_equal(frames[10], decode(video)[1][10])  # something was drawn
    assert plot.stat().st_size > 0


def test_scale_rows_past_the_end_and_boxes_off_the_frame(
    scene_files: tuple[Scene, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene, video, _ = scene_files
    big = scene.truth.copy()
    big[:, 2:6] *= 4  # the truth in a frame 4 times as large
    late = np.vstack([big, big[-1:] + [5, 0, 0, 0, 0, 0, 0, 0, 0, 0]])
    tracks = tmp_path / "big.txt"
    write_mot(tracks, late)
    argv = ["render", str(video), str(tracks)]
    assert main([*argv, "--out", str(tmp_path / "a.mp4")]) == 0
    err = capsys.readouterr().err
    assert "reach outside the" in err and "(--scale S)" in err
    assert "1 row of frame 35 is past the video's last frame 30: not drawn" in err
    assert main([*argv, "--scale", "0.25", "--out", str(tmp_path / "b.mp4")]) == 0
    assert "outside" not in capsys.readouterr().err
    # boxes 1.6 times too large mostly cross the frame's edge without lying wholly outside
    assert main([*argv, "--scale", "0.4", "--out", str(tmp_path / "c.mp4")]) == 0
    assert "reach outside the" in capsys.readouterr().err
    # every row past the video: another video's tracks, refused before any work (a user
    # trial: exit 0 and a video with nothing drawn, said only by the summary)
    past = tmp_path / "past.txt"
    write_mot(past, scene.truth + [100, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    assert main(["render", str(video), str(past), "--out", str(tmp_path / "d.mp4")]) == 2
    assert capsys.readouterr().err == (
        f"pftrack render: error: every row of {past} lies past the last frame of {video}, "
        "which has 30 (the rows' frames are 101-130): the tracks of another video?\n"
    )
    assert not (tmp_path / "d.mp4").exists()
    _, drawn = decode(tmp_path / "b.mp4")
    rows = read_mot(tracks)
    rows[:, 2:6] *= 0.25
    src = FrameSource(video)
    ref = write_annotated_video(tmp_path / "ref.mp4", src, rows, src.fps)
    assert all(np.array_equal(a, b) for a, b in zip(drawn, decode(ref)[1], strict=True))


def test_bad_input_is_one_line_and_nothing_is_lost(
    scene_files: tuple[Scene, Path, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, video, truth = scene_files
    kept = tmp_path / "kept.mp4"
    with VideoWriter(kept, fps=5) as writer:  # an earlier render: pftrack replaces no other
        writer.write(np.zeros((16, 16, 3), np.uint8))
    earlier = kept.read_bytes()

    def error(*argv: str) -> str:
        assert main(["render", *argv]) == 2
        text = capsys.readouterr().err.strip()
        assert text.count("\n") == 0 and text.startswith("pftrack render: error: "), text
        return text

    # as recover and smooth word it (was "tracks file PATH: no such file")
    none = tmp_path / "none.txt"
    assert error(str(video), str(none), "--out", str(kept)).endswith(
        f"error: tracks file not found: {none}"
    )
    # was "tracks file /dev/stdin: is not a regular file" (a stray colon)
    assert error(str(video), "/dev/null", "--out", str(kept)).endswith(
        "error: tracks file /dev/null is not a regular file (a device, pipe or socket)"
    )
    assert ".webm" in error(str(video), str(truth), "--out", str(tmp_path / "v.webm"))
    assert "--trail is -1" in error(str(video), str(truth), "--out", str(kept), "--trail", "-1")
    bad = tmp_path / "bad.txt"
    bad.write_text("1,1,0,0,-5,10,1,-1,-1,-1\n")
    assert "negative" in error(str(video), str(bad), "--out", str(kept))
    before = video.read_bytes()
    assert "is an input" in error(str(video), str(truth), "--out", str(video))  # never the input
    assert kept.read_bytes() == earlier and video.read_bytes() == before


@pytest.mark.parametrize(
    ("command", "option", "limits"),
    [(["render", "V", "T", "--out", "O"], "--trail", "0 to 100000"),
     (["demo"], "--particles", "1 to 1000000"),
     (["track", "V", "--out", "O"], "--open-size", "0 to 255")],
)  # fmt: skip
def test_help_states_the_limits_it_enforces(
    command: list[str], option: str, limits: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main([command[0], "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert limits in text.split(f"{option} ")[-1].split(" --")[0]  # its help, not the usage
    try:  # enforced: refused by argparse (SystemExit) or by the command (exit status 2)
        status = main([*command, option, str(int(limits.split(" to ")[1]) + 1)])
    except SystemExit as exc:
        status = exc.code  # type: ignore[assignment]
    assert status == 2


@pytest.mark.parametrize("command", ["track", "render"])
def test_fps_help_names_every_place_the_rate_comes_from(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """FrameSource takes a rate from the frames' time stamps when the header has none, or a
    time base (Matroska's 1000 "fps"): ``--fps``'s default said only "seqinfo.ini's
    frameRate, else the container's header, else 25"."""
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    help_of_fps = text.split("--fps FPS ")[-1].split("else 25)")[0]  # its help, not the usage
    assert "else the container's header, else the frames' time stamps" in help_of_fps


def test_rows_past_a_folder_whose_names_skip_numbers_say_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Images 1, 6, 11, 16 and another tool's rows numbered by the names: frame k is drawn on
    the k-th image. Was said only as "rows of frames 6-16 are past the video's last frame 4",
    the words of another video's tracks; the names that skip numbers are now named."""
    scene = make_scene(n_frames=4, width=64, height=64, n_walkers=1, rng=0)
    folder = tmp_path / "imgs"
    scene.write_images(folder)
    for k, path in enumerate(sorted(folder.iterdir()), start=0):
        path.rename(folder / f"{1 + 5 * k}.png")
    rows = scene.truth[:4].copy()
    rows[:, 0] = [1, 6, 11, 16]
    write_mot(tmp_path / "t.txt", rows)
    assert main(["-q", "render", str(folder), str(tmp_path / "t.txt"), "--out",
                 str(tmp_path / "v.mp4")]) == 0  # fmt: skip
    err = capsys.readouterr().err
    assert err == (
        "pftrack render: warning: 3 rows of frames 6-16 are past the video's last frame 4: not "
        f"drawn ({folder}: image 2 is missing (names 1..16 skip numbers): row frame k is drawn "
        "on the k-th image)\n"
    )


@pytest.mark.parametrize("command", ["track", "render"])
def test_frames_too_wide_for_h264_are_refused_before_any_work(
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A 20000x64 panorama into an .mp4: was a traceback (PyAV's "Generic error in an external
    library: avcodec_open2") and exit status 1 after the first frame; now one line naming the
    option, before any work, and nothing written."""
    import cv2

    import pftrack.tracking as tracking

    folder = tmp_path / "pano"
    folder.mkdir()
    for k in (1, 2):
        cv2.imwrite(str(folder / f"{k}.png"), np.full((64, 20001, 3), 90 * k, np.uint8))
    write_mot(tmp_path / "t.txt", np.array([[1, 1, 10, 10, 20, 40, 1, -1, -1, -1]], float))

    def refuse(*args: object, **kwargs: object) -> None:
        raise AssertionError("work started before the size was checked")

    monkeypatch.setattr(tracking, "track_frames", refuse)
    monkeypatch.chdir(tmp_path)
    if command == "track":
        argv, what = ["track", "pano", "--out", "o.txt", "--render", "v.mp4"], "--render"
    else:
        argv, what = ["render", "pano", "t.txt", "--out", "v.mp4"], "--out"
    before = sorted(p.name for p in tmp_path.iterdir())
    assert main(["-q", *argv]) == 2
    assert capsys.readouterr().err == (
        f"pftrack {command}: error: {what} v.mp4: H.264 takes frames up to 16384 pixels a side "
        "(x264), not 20002x64; write an .avi (Motion-JPEG) instead\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_the_plot_title_says_what_it_shows_and_the_plot_what_the_video_does(
    scene_files: tuple[Scene, Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Was the sequence's name alone: not what the lines are, nor of how many tracks; and the
    plot drew the rows past the video's end that the warning says are not drawn."""
    import pftrack.render

    scene, video, _ = scene_files
    tracks = tmp_path / "late.txt"
    write_mot(tracks, np.vstack([scene.truth, [35, 99, 10, 10, 5, 9, 1, -1, -1, -1]]))
    calls = []
    real = pftrack.render.plot_trajectories

    def spy(path: Path, rows: np.ndarray, *args: object, title: str = "", **kw: object) -> Path:
        calls.append((rows, title))
        return real(path, rows, *args, title=title, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(pftrack.render, "plot_trajectories", spy)
    argv = ["-q", "render", str(video), str(tracks), "--out", str(tmp_path / "v.mp4")]
    assert main([*argv, "--plot", str(tmp_path / "p.png")]) == 0
    [(rows, title)] = calls
    assert title == "scene.avi: foot-point paths of 3 tracks, frames 1-30"
    assert len(rows) == len(scene.truth) and rows[:, 0].max() == 30


@pytest.mark.parametrize("command", ["track", "render"])
def test_the_plot_is_drawn_on_the_first_frame_that_is_not_dark(
    command: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A video that fades in from black (or starts with the lens cap on) was plotted on its
    black frame 1: the paths on a black picture, not on the scene."""
    import pftrack.render

    scene = make_scene(n_frames=20, n_walkers=2, rng=0)
    scene.frames[:4] = [np.zeros_like(f) for f in scene.frames[:4]]  # dark, as a fade-in
    scene.frames[4] = (scene.frames[4] // 40).astype(np.uint8)  # dark too: mean level <= 8
    folder = scene.write_images(tmp_path / "imgs")
    tracks = tmp_path / "truth.txt"
    write_mot(tracks, scene.truth)
    backgrounds = []
    real = pftrack.render.plot_trajectories

    def spy(path: Path, rows: np.ndarray, *args: object, background: np.ndarray, **kw: object
            ) -> Path:  # fmt: skip
        backgrounds.append(background)
        return real(path, rows, *args, background=background, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(pftrack.render, "plot_trajectories", spy)
    plot = ["--plot", str(tmp_path / "p.png")]
    if command == "track":
        argv = ["track", str(folder), "--out", str(tmp_path / "t.txt"), *plot]
    else:
        argv = ["render", str(folder), str(tracks), "--out", str(tmp_path / "v.mp4"), *plot]
    assert main(["-q", *argv]) == 0
    [background] = backgrounds
    assert np.array_equal(background, scene.frames[5])  # frame 6, the first not dark (PNG)


def test_a_video_dark_throughout_is_plotted_on_its_first_frame(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import pftrack.render

    scene = make_scene(n_frames=6, n_walkers=1, rng=0)
    scene.frames[:] = [(f // 40).astype(np.uint8) for f in scene.frames]
    folder = scene.write_images(tmp_path / "imgs")
    tracks = tmp_path / "truth.txt"
    write_mot(tracks, scene.truth)
    backgrounds = []
    monkeypatch.setattr(
        pftrack.render,
        "plot_trajectories",
        lambda *a, background, **k: backgrounds.append(background),
    )
    argv = ["render", str(folder), str(tracks), "--out", str(tmp_path / "v.mp4")]
    assert main(["-q", *argv, "--plot", str(tmp_path / "p.png")]) == 0
    assert np.array_equal(backgrounds[0], scene.frames[0])
