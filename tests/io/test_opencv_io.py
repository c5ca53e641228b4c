"""File names that are not valid UTF-8 reach OpenCV never as such: no crash, the same pixels.

OpenCV's binding crashes the process (a segmentation fault) on ``cv2.VideoCapture``,
``cv2.imread``, ``cv2.imwrite`` and ``cv2.VideoWriter`` given such a name; the command-line
test runs ``pftrack`` in a subprocess, where a crash is an exit status of -11.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
import pytest

from pftrack.io.opencv_io import (
    is_utf8,
    opencv_name,
    printable,
    read_image,
    utf8_name,
    write_image,
)
from pftrack.io.video import FrameSource
from pftrack.io.video_writer import VideoWriter
from pftrack.synthetic import make_scene


def _latin1(folder: Path, name: bytes) -> Path:
    """`folder`/`name` (bytes that are not UTF-8); skip where the file system refuses them."""
    path = Path(os.fsdecode(os.path.join(os.fsencode(folder), name)))
    try:
        path.touch()
        path.unlink()
    except OSError:  # e.g. macOS: names must be UTF-8
        pytest.skip("this file system takes only UTF-8 names")
    return path


@pytest.fixture(autouse=True)
def _own_tempdir(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test's scratch links in a folder of its own: another process's don't count."""
    own = tmp_path_factory.mktemp("tempdir")
    monkeypatch.setattr(tempfile, "tempdir", str(own))


def _pftrack_scratch() -> set[str]:
    return {n for n in os.listdir(tempfile.gettempdir()) if n.startswith("pftrack-")}


def test_names_are_told_apart_and_shown_with_escapes(tmp_path: Path) -> None:
    bad = _latin1(tmp_path, b"vid\xfe.mp4")
    assert is_utf8(tmp_path / "vidé.mp4") and not is_utf8(bad)
    assert printable(bad).endswith("vid\\xfe.mp4")


def test_images_are_written_and_read_under_any_name(tmp_path: Path) -> None:
    image = make_scene(n_frames=1, rng=0).frames[0]
    good, bad = tmp_path / "a.png", _latin1(tmp_path, b"b\xe9.png")
    assert cv2.imwrite(str(good), image)
    write_image(bad, image)
    assert bad.read_bytes() == good.read_bytes()  # cv2.imwrite's bytes
    got = read_image(bad)
    assert got is not None and np.array_equal(got, image)
    assert read_image(_latin1(tmp_path, b"missing\xe9.png")) is None
    assert len(os.listdir(tmp_path)) == 2  # no temporary file


def test_a_truncated_jpeg_is_read_under_any_name_as_under_a_utf8_one(tmp_path: Path) -> None:
    """libjpeg decodes a cut file, the rest grey (pftrack warns of it: video.py's _cut_jpeg).

    Was: under a name that is not UTF-8, read from memory (``cv2.imdecode``), it could not be
    read at all: a folder tracked under one name failed under another.
    """
    image = make_scene(n_frames=1, rng=0).frames[0]
    data = cv2.imencode(".jpg", image)[1].tobytes()
    good, bad = tmp_path / "a.jpg", _latin1(tmp_path, b"b\xe9.jpg")
    for path in (good, bad):
        path.write_bytes(data[: len(data) // 2])
    before = _pftrack_scratch()
    want, got = read_image(good, notes=[]), read_image(bad, notes=[])
    assert want is not None and got is not None and np.array_equal(got, want)
    assert _pftrack_scratch() == before  # no link left behind


def test_a_video_and_an_image_folder_under_any_name_give_the_same_frames(
    tmp_path: Path,
) -> None:
    scene = make_scene(n_frames=6, rng=0)
    before = _pftrack_scratch()
    video = scene.write_video(_latin1(tmp_path, b"v\xfe.avi"))
    folder = scene.write_images(_latin1(tmp_path, b"imgs\xe9"))
    good = scene.write_video(tmp_path / "v.avi")
    expected = list(FrameSource(good))
    for source, want in ((video, expected), (folder, scene.frames)):
        frames = list(FrameSource(source))
        assert len(frames) == 6
        assert all(np.array_equal(a, b) for a, b in zip(frames, want, strict=True))
    assert len(FrameSource(video).frames_at([1, 4])) == 2
    assert _pftrack_scratch() == before  # the links to the files are gone


def test_video_writer_writes_avi_under_any_name(tmp_path: Path) -> None:
    frames = make_scene(n_frames=4, rng=0).frames
    out = _latin1(tmp_path, b"r\xfe.avi")
    with VideoWriter(out, 10.0) as writer:
        for frame in frames:
            writer.write(frame)
    assert len(list(FrameSource(out))) == 4
    assert sorted(os.listdir(tmp_path)) == [os.path.basename(out)]


def test_opencv_name_is_the_path_itself_when_it_is_utf8(tmp_path: Path) -> None:
    with opencv_name(tmp_path / "vidé.avi") as name:
        assert name == str(tmp_path / "vidé.avi")


def test_track_reads_and_writes_names_that_are_not_utf8(tmp_path: Path) -> None:
    """Was: a segmentation fault (exit status -11, 139 in a shell) for each of these."""
    scene = make_scene(n_frames=8, rng=0)
    video = scene.write_video(tmp_path / "v.avi")
    folder = scene.write_images(tmp_path / "imgs")
    bad_video = _latin1(tmp_path, b"vid\xfe.avi")
    bad_video.write_bytes(video.read_bytes())
    bad_folder = _latin1(tmp_path, b"imgs\xe9")
    folder.rename(bad_folder)
    plot, render, out = (_latin1(tmp_path, n) for n in (b"p\xfe.png", b"r\xfe.avi", b"d\xfe.txt"))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), "PYTHONIOENCODING": "utf-8"}
    runs = {
        "video, its name the plot's title": [bad_video, "--out", "a.txt", "--plot", "a.png"],
        "image folder": [bad_folder, "--out", "b.txt"],
        "plot and render": [video, "--out", "c.txt", "--plot", plot, "--render", render],
        "summary on a strict stdout": [video, "--out", out],
    }
    for case, args in runs.items():
        argv = [sys.executable, "-m", "pftrack", "-q", "track", *map(str, args)]
        run = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, timeout=120,
                             check=False)  # fmt: skip
        assert run.returncode == 0, (case, run.returncode, run.stderr)
    assert all(p.stat().st_size > 0 for p in (plot, render, out))
    assert {"a.txt", "a.png", "b.txt", "c.txt"} <= set(os.listdir(tmp_path))
    assert not [n for n in os.listdir(tmp_path) if n.startswith(".")]  # no temporary file


def test_a_stream_url_that_is_not_utf8_is_refused() -> None:
    with pytest.raises(ValueError, match=r"stream URL rtsp://host/\\xfe is not valid UTF-8"):
        FrameSource(os.fsdecode(b"rtsp://host/\xfe"))


def _escaped(path: Path) -> str:
    """`path` as Python spells it under ``LC_ALL=C``: its UTF-8 bytes as surrogate escapes.

    As in the child of the subprocess test below, which makes its names itself.
    """
    return os.fsencode(path).decode("ascii", "surrogateescape")


def test_opencv_gets_the_utf8_text_of_a_name_spelt_with_surrogate_escapes(tmp_path: Path) -> None:
    good = tmp_path / "vidé o.avi"
    assert _escaped(good) != str(good) and is_utf8(_escaped(good))
    assert utf8_name(_escaped(good)) == str(good)
    with opencv_name(_escaped(good)) as name:
        assert name == str(good)
    with pytest.raises(ValueError, match=r"not valid UTF-8"):
        utf8_name(os.fsdecode(b"vid\xfe.avi"))
    with pytest.raises(ValueError, match=r"cannot write image .*\(format '\.p\\udcfeng'\)"):
        write_image(os.fsdecode(b"p.p\xfeng"), np.zeros((4, 4, 3), np.uint8))  # was: a crash


def test_files_named_with_surrogate_escapes_of_utf8_are_read_and_written(tmp_path: Path) -> None:
    """Was: a segmentation fault in ``cv2.VideoCapture``, ``cv2.imread`` (under ``LC_ALL=C``,
    ``pftrack track "vidé o.avi"`` gets ``"vid\\udcc3\\udca9 o.avi"``); run in a subprocess,
    where a crash is an exit status, not the end of the tests."""
    scene = make_scene(n_frames=4, rng=0)
    scene.write_video(tmp_path / "vidé o.avi")
    scene.write_images(tmp_path / "imgé")
    code = (  # the names made in the child: an argument reaches it decoded anew
        "import os, sys\n"
        "from pftrack.io.opencv_io import read_image, write_image\n"
        "from pftrack.io.video import FrameSource\n"
        "from pftrack.io.video_writer import VideoWriter\n"
        "def escaped(name):\n"
        "    path = os.fsencode(os.path.join(sys.argv[1], name))\n"
        "    return path.decode('ascii', 'surrogateescape')\n"
        "video, folder, image, out, written = map(escaped, sys.argv[2:])\n"
        "assert '\\udcc3\\udca9' in video\n"
        "frames = list(FrameSource(video))\n"
        "assert len(frames) == 4 and len(list(FrameSource(folder))) == 4\n"
        "assert read_image(image) is not None\n"
        "write_image(written, frames[0])\n"
        "with VideoWriter(out, 10.0, backend='opencv') as writer:\n"
        "    writer.write(frames[0])\n"
    )
    names = ["vidé o.avi", "imgé", "imgé/000001.png", "outé.avi", "writtené.png"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    run = subprocess.run(
        [sys.executable, "-c", code, str(tmp_path), *names],
        env=env,
        capture_output=True,
        timeout=60,
        check=False,
    )
    assert run.returncode == 0, (run.returncode, run.stderr)
    assert (tmp_path / "outé.avi").stat().st_size > 0
    assert (tmp_path / "writtené.png").stat().st_size > 0


def test_track_under_the_c_locale_reads_a_utf8_name(tmp_path: Path) -> None:
    """Was: exit status 139 for ``LC_ALL=C pftrack track "vidé o.avi" --out t.txt``."""
    make_scene(n_frames=6, rng=0).write_video(tmp_path / "vidé o.avi")
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(sys.path),
        "LC_ALL": "C",
        "PYTHONUTF8": "0",
        "PYTHONCOERCECLOCALE": "0",
    }
    env.pop("PYTHONIOENCODING", None)
    argv = [sys.executable, "-m", "pftrack", "-q", "track", "vidé o.avi".encode(), "--out", "t.txt"]
    run = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, timeout=120,
                         check=False)  # fmt: skip
    assert run.returncode == 0, (run.returncode, run.stderr)
    assert (tmp_path / "t.txt").stat().st_size > 0


def test_reading_an_image_leaves_no_unclosed_file_at_exit(tmp_path: Path) -> None:
    # the file stderr is held in during a decode is closed at exit, not left to the garbage
    # collector (a ResourceWarning under `python -X dev`, pytest and every warnings filter)
    image = tmp_path / "a.png"
    write_image(image, np.zeros((4, 4, 3), np.uint8))
    script = (
        "import sys; from pftrack.io.opencv_io import read_image; read_image(sys.argv[1], notes=[])"
    )
    run = subprocess.run(
        [sys.executable, "-X", "dev", "-c", script, str(image)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "ResourceWarning" not in run.stderr, run.stderr


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_fork_while_another_thread_reads_an_image_leaves_the_child_free(tmp_path: Path) -> None:
    # was: a fork (multiprocessing's default on Linux before Python 3.14) while a reading thread
    # held file descriptor 2 gave the child the lock taken for good, its first image read with
    # notes (FrameSource of an image folder) hung, and its stderr went to the parent's file
    import threading
    import time

    from pftrack.io import opencv_io

    image = write_image(tmp_path / "1.png", np.full((8, 8, 3), 90, np.uint8))
    stderr_before = os.fstat(2)
    inside, leave = threading.Event(), threading.Event()

    def reader() -> None:  # a thread of the parent, caught half-way through a read
        with opencv_io._decoder_notes([]):
            inside.set()
            leave.wait(10)

    thread = threading.Thread(target=reader)
    thread.start()
    assert inside.wait(10)
    threading.Timer(0.3, leave.set).start()  # a read ends soon: the fork may wait for it
    pid = os.fork()
    if pid == 0:  # the child: read an image, stderr the parent's own
        code = 1
        try:
            got = read_image(image, notes=[])
            same = os.fstat(2)
            code = 0 if got is not None and same.st_ino == stderr_before.st_ino else 3
        finally:
            os._exit(code)
    leave.set()
    thread.join(10)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        time.sleep(0.05)
    else:
        os.kill(pid, 9)
        os.waitpid(pid, 0)
        pytest.fail("the forked child hung reading an image")
    assert os.waitstatus_to_exitcode(status) == 0
