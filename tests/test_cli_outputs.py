"""Every command checks its outputs before any work, fails in one line, and never loses a file.

The cases (one parametrised row each) are the table of docs/robustness.md: for each command,
an output that is a folder, in a missing folder, in an unwritable folder, with an unsupported
extension, or naming an input; each must end in ``pftrack CMD: error: ...`` on one line, exit
status 2, with the existing outputs byte for byte as they were and no stray temporary file.
"""

from __future__ import annotations

import errno
import os
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import write_mot
from pftrack.io.video_writer import VideoWriter
from pftrack.synthetic import make_scene
from tests.earlier_outputs import TRACKS, write_earlier

ROOT = os.geteuid() == 0 if hasattr(os, "geteuid") else False


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("inputs")
    scene = make_scene(n_frames=20, rng=0)
    video = scene.write_video(d / "scene.avi")
    gt = scene.write_truth(d / "gt.txt")
    tracks = d / "tracks.txt"
    rows = scene.truth[np.isin(scene.truth[:, 0], np.r_[1:8, 13:21])]  # a gap in every track
    write_mot(tracks, rows)
    return {"video": video, "gt": gt, "tracks": tracks}


def _unwritable(tmp: Path) -> Path:
    """A folder this process cannot create files in (root ignores mode bits: use /sys)."""
    if ROOT:
        if not Path("/sys").is_dir():
            pytest.skip("running as root without /sys: no unwritable folder")
        return Path("/sys")
    d = tmp / "ro"
    d.mkdir()
    d.chmod(0o555)
    return d


# (name, command builder): the builder gets the inputs, the bad output path and the temp folder
Builder = Callable[[dict[str, Path], Path | str, Path], list[str]]
COMMANDS: dict[str, Builder] = {
    "track --out": lambda i, o, t: ["track", str(i["video"]), "--out", str(o), "--particles", "20"],
    "track --render": lambda i, o, t: [
        "track",
        str(i["video"]),
        "--out",
        str(t / "t_ok.txt"),
        "--render",
        str(o),
        "--particles",
        "20",
    ],  # fmt: skip
    "track --plot": lambda i, o, t: [
        "track",
        str(i["video"]),
        "--out",
        str(t / "t_ok.txt"),
        "--plot",
        str(o),
        "--particles",
        "20",
    ],  # fmt: skip
    "smooth --out": lambda i, o, t: ["smooth", str(i["tracks"]), "--out", str(o)],
    "recover --out": lambda i, o, t: [
        "recover",
        str(i["tracks"]),
        "--out",
        str(o),
        "--method",
        "linear",
    ],  # fmt: skip
    "eval --json": lambda i, o, t: [
        "eval",
        "--gt",
        str(i["gt"]),
        "--res",
        str(i["tracks"]),
        "--json",
        str(o),
    ],  # fmt: skip
    "experiment --json": lambda i, o, t: [
        "experiment",
        "gaps",
        "--gt",
        str(i["gt"]),
        "--json",
        str(o),
    ],  # fmt: skip
    "experiment --figure": lambda i, o, t: [
        "experiment",
        "gaps",
        "--gt",
        str(i["gt"]),
        "--figure",
        str(o),
    ],  # fmt: skip
}
GOOD_NAME = {"track --render": "v.mp4", "track --plot": "p.png", "eval --json": "m.json",
             "experiment --json": "e.json", "experiment --figure": "f.png"}  # fmt: skip


def _bad_output(case: str, command: str, inputs: dict[str, Path], tmp: Path) -> Path | str:
    name = GOOD_NAME.get(command, "out.txt")
    if case == "new folder with a trailing slash":  # was: a file named `newdir` written
        return f"{tmp / 'newdir'}/"
    if case == "-":  # was: a file named `-` written (the test runs in `tmp`)
        return "-"
    if case == "empty":  # was: "--out . is a folder; give a file name", or (--render, --plot,
        # --json, --csv, --figure) nothing written and nothing said
        return ""
    if case == "under a file":  # was: "folder t_ok.txt does not exist" (it does, as a file)
        return tmp / "t_ok.txt" / name
    if case == "existing folder":
        (tmp / name).mkdir()
        return tmp / name
    if case == "missing folder":
        return tmp / "no" / "such" / name
    if case == "unwritable folder":
        return _unwritable(tmp) / name
    if case == "unsupported extension":
        if command not in GOOD_NAME:
            pytest.skip("text outputs take any extension")
        return tmp / "out.xyz"
    if case in ("a video", "a picture"):  # was: the video replaced by text, exit 0
        if command in GOOD_NAME:
            pytest.skip("media outputs: their extension is checked (covered above)")
        name = "annotated.mp4" if case == "a video" else "paths.png"
        (tmp / name).write_bytes(b"\x00\x00\x00\x18ftypmp42\x00 a user's video or picture")
        return tmp / name
    if case == "an input":
        key = "gt" if command == "eval --json" else "tracks"
        if command.startswith("track"):
            key = "video"
        if command in GOOD_NAME:
            pytest.skip("its extension check comes first (covered above)")
        return inputs[key]
    raise AssertionError(case)


CASES = ["existing folder", "missing folder", "unwritable folder", "unsupported extension",
         "an input", "new folder with a trailing slash", "-", "empty", "under a file", "a video",
         "a picture"]  # fmt: skip
#: The whole message of a case, after ``pftrack CMD: error: `` (OPTION, OUT, TMP filled in).
MESSAGES = {
    "empty": "{option} is empty; give a file name",
    "under a file": "{option} {out}: {tmp}/t_ok.txt is a file, not a folder",
    "a video": "{option} {out} is an existing file that is not text (a video? a picture?), and "
    "{option} writes the tracks as MOTChallenge text over it: give a .txt name (--render and "
    "pftrack render write videos, --plot pictures)",
}


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    return {p.name: (p.read_bytes() if p.is_file() else None) for p in folder.iterdir()}


def _no_work(*args: object, **kwargs: object) -> None:
    """Stands in for the work of a command whose outputs must be refused before it starts."""
    raise AssertionError("work started before the outputs were checked")


@pytest.fixture
def no_work(monkeypatch: pytest.MonkeyPatch) -> None:
    """Tracking fails the test: the command must refuse before any work."""
    import pftrack.tracking as tracking

    monkeypatch.setattr(tracking, "track_frames", _no_work)


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("command", list(COMMANDS))
def test_bad_output_is_refused_before_any_work(
    command: str,
    case: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    no_work: None,
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t_ok.txt").write_text("old tracks\n")
    out = _bad_output(case, command, inputs, tmp_path)
    before_inputs = {k: p.read_bytes() for k, p in inputs.items()}
    before = _snapshot(tmp_path)
    assert main(COMMANDS[command](inputs, out, tmp_path)) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    prog = "experiment gaps" if command.startswith("experiment") else command.split()[0]
    assert len(lines) == 1 and lines[0].startswith(f"pftrack {prog}: error: "), err
    if case in MESSAGES:
        said = MESSAGES[case].format(option=command.split()[1], out=out, tmp=tmp_path)
        assert lines[0] == f"pftrack {prog}: error: {said}"
    assert _snapshot(tmp_path) == before  # nothing changed, nothing left behind
    assert {k: p.read_bytes() for k, p in inputs.items()} == before_inputs


def _read_only(monkeypatch: pytest.MonkeyPatch, folder: Path) -> None:
    """Make `folder` act as on a read-only file system, as a user other than root sees it.

    ``access()`` says no for writing, and creating a file or folder in it fails with EROFS.
    """
    inside = str(folder)
    real_open, real_mkdir, real_access = os.open, os.mkdir, os.access

    def under(path: Any) -> bool:
        return os.path.dirname(os.path.abspath(os.fsdecode(path))) == inside

    def open_(path: Any, flags: int, mode: int = 0o777, **kw: Any) -> int:
        if under(path) and flags & os.O_CREAT:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), path)
        return real_open(path, flags, mode, **kw)

    def mkdir(path: Any, mode: int = 0o777, **kw: Any) -> None:
        if under(path):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), path)
        real_mkdir(path, mode, **kw)

    def access(path: Any, mode: int, **kw: Any) -> bool:
        if os.path.abspath(os.fsdecode(path)) == inside and mode & os.W_OK:
            return False
        return real_access(path, mode, **kw)

    monkeypatch.setattr(os, "open", open_)
    monkeypatch.setattr(os, "mkdir", mkdir)
    monkeypatch.setattr(os, "access", access)


@pytest.mark.parametrize("command", ["demo --out-dir", *COMMANDS])
def test_an_output_on_a_read_only_file_system_says_so(
    command: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A user trial (EROFS): ``demo`` said "(Permission denied)", the other commands "not
    writable", neither why."""
    import pftrack.demo  # noqa: F401  imported unpatched: it binds track_frames at import
    import pftrack.tracking as tracking

    monkeypatch.setattr(tracking, "track_frames", _no_work)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t_ok.txt").write_text("old tracks\n")
    ro = tmp_path / "ro"
    ro.mkdir()
    if command == "demo --out-dir":
        argv = ["demo", "--out-dir", str(ro / "d"), "--frames", "5"]
    else:
        argv = COMMANDS[command](inputs, ro / GOOD_NAME.get(command, "out.txt"), tmp_path)
    _read_only(monkeypatch, ro)
    assert main(argv) == 2
    err = capsys.readouterr().err
    prog = "experiment gaps" if command.startswith("experiment") else command.split()[0]
    assert err.startswith(f"pftrack {prog}: error: {command.split()[1]} {ro}")
    assert err.count("\n") == 1 and "(read-only file system)" in err, err
    assert not any(ro.iterdir())


def test_demo_refuses_a_file_as_its_folder_and_a_folder_as_an_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["demo", "--out-dir", str(f), "--frames", "5"]) == 2
    assert capsys.readouterr().err.startswith("pftrack demo: error: --out-dir")
    (tmp_path / "d" / "annotated.mp4").mkdir(parents=True)
    assert main(["demo", "--out-dir", str(tmp_path / "d"), "--frames", "5"]) == 2
    # the folder in the way is named inside --out-dir; was "--out-dir d/annotated.mp4 is a
    # folder; give a file name", a name the user cannot give
    d = tmp_path / "d"
    assert capsys.readouterr().err == (
        f"pftrack demo: error: --out-dir {d}: {d}/annotated.mp4 is a folder, where this "
        "command writes a file; move it, or give another --out-dir\n"
    )
    assert sorted(p.name for p in (tmp_path / "d").iterdir()) == ["annotated.mp4"]


@pytest.mark.filterwarnings("ignore:no track over 5 frames")  # 5 frames: no track confirmed
@pytest.mark.parametrize("mine", [["tracks.txt"], ["truth.txt", "trajectories.png"]])
def test_demo_does_not_replace_a_users_file_of_one_of_its_names(
    mine: list[str],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``pftrack demo --out-dir .`` where ``pftrack track ... --out tracks.txt`` had written:
    was exit 0, the user's tracks replaced by the demo's. An earlier demo's folder is still
    written over (its record gives each file's SHA-256); other files are refused before work."""
    import pftrack.demo

    for name in mine:
        (tmp_path / name).write_text("the user's own\n")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    with monkeypatch.context() as m:
        m.setattr(pftrack.demo, "track_frames", _no_work)
        assert main(["demo", "--out-dir", str(tmp_path), "--frames", "5"]) == 2
    listed, it = ", ".join(mine), "it" if len(mine) == 1 else "them"
    assert capsys.readouterr().err == (
        f"pftrack demo: error: --out-dir {tmp_path} holds {listed}, but no record that pftrack "
        f"demo wrote {it} (.pftrack-demo.json): not the demo's to replace; move {it}, or give "
        "another --out-dir\n"
    )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    out = tmp_path / "d"  # an earlier demo's folder is written again
    for _ in range(2):
        assert main(["-q", "demo", "--out-dir", str(out), "--frames", "5"]) == 0
    names = ["annotated.mp4", "tracks.txt", "trajectories.png", "truth.txt"]
    assert sorted(p.name for p in out.iterdir()) == [".pftrack-demo.json", *names]


@pytest.mark.filterwarnings("ignore:no track over 5 frames")  # 5 frames: no track confirmed
def test_demo_does_not_replace_a_users_file_put_in_place_of_an_earlier_demos(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A user trial: an earlier demo's folder whose tracks.txt the user had replaced by their
    own was written over (exit 0), as its four names were all there. Now a file of the demo's
    names is its own only if the demo's record gives its SHA-256."""
    import pftrack.demo

    assert main(["-q", "demo", "--out-dir", str(tmp_path), "--frames", "5"]) == 0
    (tmp_path / "tracks.txt").write_text("1,1,10,10,20,40,1,-1,-1,-1\n")  # the user's own
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    with monkeypatch.context() as m:
        m.setattr(pftrack.demo, "track_frames", _no_work)
        assert main(["demo", "--out-dir", str(tmp_path), "--frames", "5"]) == 2
        assert capsys.readouterr().err == (
            f"pftrack demo: error: --out-dir {tmp_path}: tracks.txt is not the file an earlier "
            "pftrack demo wrote there (.pftrack-demo.json records another): not the demo's to "
            "replace; move it, or give another --out-dir\n"
        )
        (tmp_path / ".pftrack-demo.json").unlink()  # four files, no record: not known as its
        assert main(["demo", "--out-dir", str(tmp_path), "--frames", "5"]) == 2
        assert "but no record that pftrack demo wrote them" in capsys.readouterr().err
    del before[".pftrack-demo.json"]
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_demo_help_says_its_folder_is_created_with_its_parents_unlike_a_files_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A user report: ``demo --out-dir a/b/c`` made a, b and c without a word, while ``track
    --out missing/dir/t.txt`` is refused. Output folders are created (demo, batch), a file's
    folder must exist; the help says so."""
    for command in ("demo", "batch"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        assert "(created, with any missing parent folders" in text
    out = tmp_path / "missing" / "dir" / "t.txt"
    assert main(["track", str(tmp_path / "v.mp4"), "--out", str(out)]) == 2
    assert capsys.readouterr().err.endswith(f"folder {out.parent} does not exist\n")


@pytest.mark.filterwarnings("ignore:no track over 5 frames")  # 5 frames: no track confirmed
@pytest.mark.parametrize("where", ["tracking", "writing"])
def test_interrupted_demo_removes_the_folder_it_made(
    where: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Was: Ctrl-C left the new --out-dir behind, empty, while saying no output was changed."""
    import pftrack.demo as demo

    def interrupt(*args: Any, **kwargs: Any) -> Any:
        raise KeyboardInterrupt

    def interrupt_after_writing(path: Any, *args: Any, **kwargs: Any) -> None:
        Path(path).write_bytes(b"half a plot")  # a staged file: removed with the others
        raise KeyboardInterrupt

    if where == "tracking":
        monkeypatch.setattr(demo, "track_frames", interrupt)
    else:
        monkeypatch.setattr(demo, "plot_trajectories", interrupt_after_writing)
    (tmp_path / "old").mkdir()
    for out_dir in (tmp_path / "new" / "deeper", tmp_path / "old"):
        assert main(["demo", "--out-dir", str(out_dir), "--frames", "5"]) == 130
        assert capsys.readouterr().err.endswith("interrupted; no output was changed\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old"]  # new/deeper: both removed
    assert list((tmp_path / "old").iterdir()) == []  # there before: kept


@pytest.mark.filterwarnings("ignore:no track over 5 frames")  # 5 frames: no track confirmed
def test_demo_interrupted_after_writing_says_its_outputs_were_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Was: Ctrl-C during the recovery demo, after the four files were in place, said "no
    output was changed"."""
    import pftrack.demo as demo

    def interrupt(*args: Any, **kwargs: Any) -> Any:
        raise KeyboardInterrupt

    monkeypatch.setattr(demo, "demo_report", interrupt)
    out_dir = tmp_path / "d"
    assert main(["demo", "--out-dir", str(out_dir), "--frames", "5"]) == 130
    assert capsys.readouterr().err == (
        f"pftrack demo: interrupted; the outputs were written before it: {out_dir}/tracks.txt, "
        "truth.txt, annotated.mp4, trajectories.png\n"
    )
    names = [".pftrack-demo.json", "annotated.mp4", "tracks.txt", "trajectories.png", "truth.txt"]
    assert sorted(p.name for p in out_dir.iterdir()) == names


def test_recover_in_place_needs_the_flag(
    inputs: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "t.txt"
    src.write_bytes(inputs["tracks"].read_bytes())
    assert main(["recover", str(src), "--out", str(src), "--method", "linear"]) == 2
    assert "--in-place" in capsys.readouterr().err
    assert src.read_bytes() == inputs["tracks"].read_bytes()
    assert main(["recover", str(src), "--out", str(src), "--method", "linear", "--in-place"]) == 0
    assert src.read_bytes() != inputs["tracks"].read_bytes()


@pytest.mark.parametrize("in_place", [False, True])
def test_recover_keeps_the_permissions_of_the_file_it_replaces(
    inputs: dict[str, Path], tmp_path: Path, in_place: bool
) -> None:
    """``chmod 600 out.txt`` survives a run that replaces it (was: reset to -rw-r--r--)."""
    src, out = tmp_path / "t.txt", tmp_path / ("t.txt" if in_place else "out.txt")
    src.write_bytes(inputs["tracks"].read_bytes())
    out.write_bytes(src.read_bytes())
    out.chmod(0o600)
    flag = ["--in-place"] if in_place else []
    assert main(["-q", "recover", str(src), "--out", str(out), "--method", "linear", *flag]) == 0
    assert out.read_bytes() != inputs["tracks"].read_bytes()
    assert out.stat().st_mode & 0o7777 == 0o600


@pytest.mark.parametrize("where", ["render", "plot", "tracking"])
def test_interrupted_track_run_changes_no_output(
    where: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Ctrl-C while the video is tracked, rendered or plotted: the old outputs stay whole."""
    import pftrack.render as render
    import pftrack.tracking as tracking

    out, video, plot = tmp_path / "t.txt", tmp_path / "v.mp4", tmp_path / "p.png"
    for p in (out, plot):
        write_earlier(p)  # an earlier run's: pftrack replaces no other
    with VideoWriter(video, fps=5) as writer:  # an earlier render: pftrack replaces no other
        writer.write(np.zeros((16, 16, 3), np.uint8))
    real_track = tracking.track_frames

    def interrupt_after_writing(path: Any, *args: Any, **kwargs: Any) -> None:
        Path(path).write_bytes(b"half a file")
        raise KeyboardInterrupt

    def interrupt_mid_video(source: Any, *args: Any, **kwargs: Any) -> Any:
        class Frames(list):  # type: ignore[type-arg]
            """The video's frames; Ctrl-C at the 11th as they are tracked (a sequence: a
            generator is refused, its frames being read twice)."""

            def __iter__(self) -> Any:
                for k in range(len(self)):
                    if k == 10:
                        raise KeyboardInterrupt
                    yield self[k]

        return real_track(Frames(source), *args, **kwargs)

    def interrupt_closing(self: Any) -> None:  # the video is encoded, not yet in place
        raise KeyboardInterrupt

    if where == "tracking":
        monkeypatch.setattr(tracking, "track_frames", interrupt_mid_video)
    elif where == "render":
        monkeypatch.setattr(render.TrackRenderer, "close", interrupt_closing)
    else:
        monkeypatch.setattr(render, "plot_trajectories", interrupt_after_writing)
    before = _snapshot(tmp_path)
    argv = ["track", str(inputs["video"]), "--out", str(out), "--render", str(video),
            "--plot", str(plot), "--particles", "20"]  # fmt: skip
    assert main(argv) == 130
    assert "interrupted" in capsys.readouterr().err
    assert _snapshot(tmp_path) == before


def test_failed_smooth_and_recover_leave_the_old_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.txt"
    bad.write_text("1,1,0,0,10,10\n2,1,0,0,ten,10\n")
    out = tmp_path / "out.txt"
    out.write_text("good\n")
    for cmd in (["smooth", str(bad), "--out", str(out)],
                ["recover", str(bad), "--out", str(out)]):  # fmt: skip
        assert main(cmd) == 2
        assert capsys.readouterr().err.count("\n") == 1
        assert out.read_text() == "good\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.txt", "out.txt"]


def _walkers(path: Path, seed: int = 4) -> Path:
    """Ground truth of 15 walkers over 150 frames of a 768x576 scene, with its seqinfo.ini."""
    rng = np.random.default_rng(seed)
    rows = []
    for tid in range(1, 16):
        xy = rng.uniform(100, 600, 2) + np.cumsum(
            rng.normal(0, 0.5, (150, 2)) + rng.uniform(-2, 2, 2), axis=0
        )
        r = np.full((150, 10), -1.0)
        r[:, 0], r[:, 1], r[:, 2:4], r[:, 4:6], r[:, 6] = np.arange(1, 151), tid, xy - 5, 10, 1
        rows.append(r)
    (path / "gt").mkdir(parents=True)
    (path / "seqinfo.ini").write_text("[Sequence]\nimWidth=768\nimHeight=576\n")
    write_mot(path / "gt" / "gt.txt", np.vstack(rows))
    return path / "gt" / "gt.txt"


# command line (VIDEO, GT, TRACKS, A and B: inputs) and outputs, run with an unread stdout
CLOSED_STDOUT = {
    "track": ("track VIDEO --out t.txt --render v.mp4 --plot p.png --particles 20",
              ["t.txt", "v.mp4", "p.png"]),
    "eval": ("eval --gt GT --res TRACKS --json s.json --csv s.csv --image-size 480 360",
             ["s.json", "s.csv"]),
    "experiment gaps --figure": (
        "experiment gaps --gt A --figure f.png --methods linear --repeat 1 --max-positions 2",
        ["f.png"],
    ),
    "experiment gaps --json": ("experiment gaps --gt A B --json e.json --methods linear",
                               ["e.json"]),
}  # fmt: skip


@pytest.mark.parametrize("buffered", [False, True], ids=["unbuffered", "buffered"])
@pytest.mark.parametrize("command", list(CLOSED_STDOUT))
def test_a_closed_stdout_loses_no_output(
    command: str, buffered: bool, inputs: dict[str, Path], tmp_path: Path
) -> None:
    """``pftrack track ... | true``: was exit 1 with no output (the summary line was printed
    before the files were committed); buffered, a traceback-like "Exception ignored" at exit."""
    import subprocess
    import sys

    line, outputs = CLOSED_STDOUT[command]
    names = {"VIDEO": inputs["video"], "GT": inputs["gt"], "TRACKS": inputs["tracks"]}
    if command.startswith("experiment"):
        names.update(A=_walkers(tmp_path / "A"), B=_walkers(tmp_path / "B", 5))
    argv = [str(names.get(a, a)) for a in line.split()]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    if not buffered:
        env["PYTHONUNBUFFERED"] = "1"
    read, write = os.pipe()
    os.close(read)  # every write to stdout fails with EPIPE, as after `| true` or `| head -0`
    try:
        run = subprocess.run([sys.executable, "-m", "pftrack", "-q", *argv], cwd=tmp_path,
                             stdout=write, stderr=subprocess.PIPE, text=True, env=env,
                             check=False, timeout=300)  # fmt: skip
    finally:
        os.close(write)
    assert run.returncode == 1 and run.stderr == "", run.stderr  # as `recover ... | head`
    for name in outputs:
        assert (tmp_path / name).stat().st_size > 0, name
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary


@pytest.mark.parametrize(
    ("first", "second"),
    [("--out", "--render"), ("--out", "--plot")],
)
@pytest.mark.parametrize("spelling", ["same", "dot", "link"])
def test_two_outputs_on_one_file_are_refused_before_any_work(
    first: str,
    second: str,
    spelling: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    no_work: None,
) -> None:
    """Was: exit 0, one output written over the other (the video lost, a CSV left)."""
    monkeypatch.chdir(tmp_path)
    name = "same.mp4" if second == "--render" else "same.png"
    (tmp_path / name).write_bytes(b"an earlier result\n")
    other = {"same": name, "dot": f"./{name}", "link": "alias" + Path(name).suffix}[spelling]
    if spelling == "link":
        (tmp_path / other).symlink_to(name)
    before = _snapshot(tmp_path)
    argv = ["track", str(inputs["video"]), first, name, second, other, "--particles", "20"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == (
        f"pftrack track: error: {first} {name} and {second} {Path(other)} are the same file; "
        "give each output its own\n"
    )
    assert _snapshot(tmp_path) == before


def test_experiment_json_and_figure_on_one_file_are_refused_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Was: exit 0, the figure written through the link into the JSON file, then the JSON over
    it (or, with both on /dev/stdout, a PNG and the JSON in one stream)."""
    monkeypatch.chdir(tmp_path)
    gt = _walkers(tmp_path / "A")
    (tmp_path / "r.json").write_text("an earlier result\n")
    (tmp_path / "alias.png").symlink_to("r.json")
    before = _snapshot(tmp_path)
    argv = ["experiment", "gaps", "--gt", str(gt), "--methods", "linear", "--repeat", "1",
            "--max-positions", "1", "--json", "r.json", "--figure", "alias.png"]  # fmt: skip
    assert main(argv) == 2
    assert capsys.readouterr().err == (
        "pftrack experiment gaps: error: --json r.json and --figure alias.png are the same "
        "file; give each output its own\n"
    )
    assert _snapshot(tmp_path) == before


def test_experiment_figure_is_kept_when_its_json_cannot_be_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: exit 2 for --json /dev/full, the user's --figure replaced by the failed run's."""
    gt = _walkers(tmp_path / "A")
    write_earlier(tmp_path / "f.png")
    before = _snapshot(tmp_path)
    argv = ["-q", "experiment", "gaps", "--gt", str(gt), "--methods", "linear", "--repeat", "1",
            "--max-positions", "1", "--json", "/dev/full",
            "--figure", str(tmp_path / "f.png")]  # fmt: skip
    assert main(argv) == 2
    assert capsys.readouterr().err.startswith("pftrack experiment gaps: error: No space left")
    assert _snapshot(tmp_path) == before


def test_check_distinct_names_both_outputs(tmp_path: Path) -> None:
    from pftrack.io.atomic import check_distinct

    check_distinct({"--json": tmp_path / "a.json", "--csv": tmp_path / "a.csv", "--x": None})
    with pytest.raises(ValueError, match=r"^--a .*x.txt and --c .*x.txt are the same file"):
        check_distinct({"--a": tmp_path / "x.txt", "--b": None, "--c": tmp_path / "." / "x.txt"})


def test_outputs_through_symlinks_replace_the_target_and_keep_the_link(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """Was: every command renamed a regular file over the link; its target kept the old text."""
    real = tmp_path / "real"
    real.mkdir()
    for name in ("t.txt", "v.mp4", "r.txt", "in.txt"):
        (real / name).write_bytes(TRACKS)  # an earlier run's
        (tmp_path / name).symlink_to(Path("real") / name)
    with VideoWriter(real / "v.mp4", fps=5) as writer:  # an earlier render: pftrack's own
        writer.write(np.zeros((16, 16, 3), np.uint8))
    (real / "in.txt").write_bytes(inputs["tracks"].read_bytes())
    argv = ["-q", "track", str(inputs["video"]), "--out", str(tmp_path / "t.txt"),
            "--render", str(tmp_path / "v.mp4"), "--particles", "20"]  # fmt: skip
    assert main(argv) == 0
    argv = ["-q", "recover", str(tmp_path / "in.txt"), "--method", "linear"]
    assert main([*argv, "--out", str(tmp_path / "r.txt")]) == 0
    assert main([*argv, "--out", str(tmp_path / "in.txt"), "--in-place"]) == 0
    for name in ("t.txt", "v.mp4", "r.txt", "in.txt"):
        assert (tmp_path / name).is_symlink(), name
        assert (real / name).read_bytes() != TRACKS, name
    assert (real / "in.txt").read_bytes() == (real / "r.txt").read_bytes()
    assert sorted(p.name for p in real.iterdir()) == ["in.txt", "r.txt", "t.txt", "v.mp4"]


@pytest.mark.parametrize("command", ["recover", "smooth", "track"])
def test_a_named_pipe_output_is_written_through(
    command: str, inputs: dict[str, Path], tmp_path: Path
) -> None:
    """Was: the pipe replaced by a regular file."""
    import threading

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    source = inputs["video"] if command == "track" else inputs["tracks"]
    extra = ["--particles", "20"] if command == "track" else []
    assert main(["-q", command, str(source), "--out", str(fifo), *extra]) == 0
    reader.join(30)
    assert got and got[0].count(b"\n") > 20 and got[0].startswith(b"1,")
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo"]


def test_out_dev_null_and_a_link_to_it_discard(
    inputs: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--out /dev/null`` (was: as root, /dev/null replaced); several outputs may share it."""
    (tmp_path / "v.mp4").symlink_to(os.devnull)
    argv = ["-q", "track", str(inputs["video"]), "--out", os.devnull,
            "--render", str(tmp_path / "v.mp4"), "--particles", "20"]  # fmt: skip
    assert main(argv) == 0
    assert f"-> {os.devnull}" in capsys.readouterr().out
    assert stat.S_ISCHR(Path(os.devnull).stat().st_mode)
    assert (tmp_path / "v.mp4").is_symlink() and sorted(os.listdir(tmp_path)) == ["v.mp4"]


def test_out_dev_stdout_prints_the_rows_and_the_summary_on_stderr(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """Through a link to /dev/stdout in the test folder (a bug would replace only the link)."""
    import subprocess
    import sys

    (tmp_path / "stdout").symlink_to("/dev/stdout")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    argv = [sys.executable, "-m", "pftrack", "-q", "recover", str(inputs["tracks"]),
            "--method", "linear", "--out", str(tmp_path / "stdout")]  # fmt: skip
    with (tmp_path / "captured.txt").open("w") as stdout:  # a file: the descriptor's offset
        run = subprocess.run(argv, stdout=stdout, stderr=subprocess.PIPE, text=True, env=env,
                             check=False, timeout=120)  # fmt: skip
    assert run.returncode == 0, run.stderr
    lines = (tmp_path / "captured.txt").read_text().splitlines()
    assert len(lines) > 20 and all(line.count(",") == 9 for line in lines)  # rows only
    assert run.stderr.startswith(f"{inputs['tracks']}: ")
    assert (tmp_path / "stdout").is_symlink()


@pytest.fixture(scope="module")
def folders(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An image folder ``imgs``, a sequence ``seq`` (``img1/``) and one read from its video."""
    d = tmp_path_factory.mktemp("folders")
    scene = make_scene(n_frames=12, rng=1)
    scene.write_images(d / "imgs")
    ini = "[Sequence]\nname={}\nimDir=img1\nframeRate=10\nseqLength=12\n"
    scene.write_images(d / "seq" / "img1")
    (d / "seq" / "seqinfo.ini").write_text(ini.format("seq"))
    (d / "vseq").mkdir()
    (d / "seq" / "gt").mkdir()
    scene.write_video(d / "vseq" / "video.avi")
    (d / "vseq" / "seqinfo.ini").write_text(ini.format("vseq"))
    write_mot(d / "vseq" / "det.txt", scene.truth)
    write_mot(d / "tracks.txt", scene.truth)
    write_mot(d / "seq" / "gt" / "gt.txt", scene.truth)
    (d / "res").mkdir()
    write_mot(d / "res" / "seq.txt", scene.truth)
    return d


# a run whose output is a file of an input folder (IN: the folder above; `link.*` a symbolic
# link made in the test folder to the file named after the arrow)
INPUT_FOLDER_CASES = {
    "track --out an image": "track IN/imgs --out IN/imgs/000001.png",
    "track --plot an image": "track IN/imgs --out o.txt --plot IN/imgs/000002.png",
    "track --plot through ..": "track IN/imgs --out o.txt --plot IN/seq/../imgs/000002.png",
    "track --render a link to an image":
        "track IN/imgs --out o.txt --render link.mp4>imgs/000003.png",
    "track --out seqinfo.ini": "track IN/vseq --detections auto --out IN/vseq/seqinfo.ini",
    "track video --out seqinfo.ini": "track IN/vseq/video.avi --out IN/vseq/seqinfo.ini",
    "track img1 --out seqinfo.ini": "track IN/seq/img1 --out IN/seq/seqinfo.ini",
    "track seq --out an image": "track IN/seq --out IN/seq/img1/000012.png",
    "track --out a link to an image": "track IN/seq --out link.txt>seq/img1/000005.png",
    "recover --video": "recover IN/tracks.txt --link --video IN/imgs --out IN/imgs/000004.png",
    "recover --video seq":
        "recover IN/tracks.txt --link --video IN/seq --out link.txt>seq/seqinfo.ini",
    "batch --out": "batch IN/imgs --workers 0 --out D link D/imgs.txt>imgs/000006.png",
    "batch --out seqinfo.ini": "batch IN/seq --workers 0 --out D link D/seq.txt>seq/seqinfo.ini",
    "eval --json": "eval --gt IN/seq --res IN/res --json link.json>seq/gt/gt.txt",
    "eval --csv": "eval --gt IN/seq --res IN/res --csv link.csv>res/seq.txt",
}  # fmt: skip


# a run whose image output would be new in the folder its frames are read from
FRAME_FOLDER_CASES = {
    "track --plot": ("track IN/imgs --out o.txt --plot IN/imgs/paths.png", "--plot", "imgs"),
    "track --plot through ..":
        ("track IN/imgs --out o.txt --plot IN/seq/../imgs/p.JPG", "--plot", "imgs"),
    "track --out": ("track IN/imgs --out IN/imgs/tracks.png", "--out", "imgs"),
    "track seq --plot": ("track IN/seq --out o.txt --plot IN/seq/img1/p.png", "--plot", "seq/img1"),
    "render --plot":
        ("render IN/imgs IN/tracks.txt --out o.mp4 --plot IN/imgs/p.png", "--plot", "imgs"),
    "recover --video": ("recover IN/tracks.txt --link --video IN/imgs --out IN/imgs/f.png",
                        "--out", "imgs"),
}  # fmt: skip


@pytest.mark.parametrize("case", list(FRAME_FOLDER_CASES))
def test_a_new_image_in_the_folder_of_the_frames_is_refused(
    case: str,
    folders: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    no_work: None,
) -> None:
    """Was: exit 0, and the next run on the folder read the plot as its last frame (a
    ``--plot imgs/paths.png`` beside ``0001.jpg .. 0020.jpg`` made 21 frames, silently)."""
    monkeypatch.chdir(tmp_path)
    line, what, folder = FRAME_FOLDER_CASES[case]
    argv = [word.replace("IN/", f"{folders}/") for word in line.split()]
    out = argv[argv.index(what) + 1]
    before = {p: p.read_bytes() for p in folders.rglob("*") if p.is_file()}
    assert main(["-q", *argv]) == 2
    assert capsys.readouterr().err == (
        f"pftrack {argv[0]}: error: {what} {out} is in {folders / folder}, whose images are "
        "this run's frames: a later run on it would read it as one more frame; write "
        "elsewhere\n"
    )
    assert {p: p.read_bytes() for p in folders.rglob("*") if p.is_file()} == before
    assert not [p for p in tmp_path.rglob("*") if p.is_file()]


def test_outputs_that_no_run_reads_as_a_frame_are_taken(folders: Path) -> None:
    """Beside the frames: a hidden image (image folders leave it out), text, a video."""
    from pftrack.io.video import check_outside_frames

    imgs = folders / "imgs"
    outputs = {"--plot": imgs / ".p.png", "--out": imgs / "t.txt", "--render": imgs / "v.mp4"}
    check_outside_frames(outputs, imgs)
    check_outside_frames({"--plot": imgs / "p.png"}, folders / "vseq")  # frames of a video


@pytest.mark.parametrize("case", list(INPUT_FOLDER_CASES))
def test_a_file_of_an_input_folder_is_not_an_output(
    case: str,
    folders: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    no_work: None,
) -> None:
    """Was: exit 0, an input image (or seqinfo.ini) replaced by the tracks, plot or video."""
    monkeypatch.chdir(tmp_path)
    argv = []
    for word in INPUT_FOLDER_CASES[case].split():
        if ">" in word:  # a link in the test folder to a file of the input folders
            name, target = word.split(">")
            (tmp_path / name).parent.mkdir(exist_ok=True)
            (tmp_path / name).symlink_to(folders / target)
            word = name
        argv.append(word.replace("IN/", f"{folders}/"))
    if "link" in argv:  # batch: the link is made, not passed
        argv = argv[: argv.index("link")]
    before = {p: p.read_bytes() for p in folders.rglob("*") if p.is_file()}
    assert main(["-q", *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.endswith("is an input of this run; write elsewhere\n"), err
    assert {p: p.read_bytes() for p in folders.rglob("*") if p.is_file()} == before
    assert not [p for p in tmp_path.rglob("*") if p.is_file() and not p.is_symlink()]


def test_sigterm_is_handled_as_ctrl_c(tmp_path: Path) -> None:
    """``kill PID`` while rendering: exit 143, outputs as they were, no temporary file.

    Was: killed where it stood (status -15, 143 in a shell), ``..t.<hex>.<hex>.mp4`` and
    ``.t.<hex>.mp4`` left beside the outputs.
    """
    import signal
    import subprocess
    import sys
    import time

    video = make_scene(n_frames=400, rng=0).write_video(tmp_path / "scene.avi")
    out = tmp_path / "out"
    out.mkdir()
    for name in ("t.txt", "t.mp4"):
        (out / name).write_bytes(TRACKS)  # an earlier result
    with VideoWriter(out / "t.mp4", fps=5) as writer:  # an earlier render: pftrack's own
        writer.write(np.zeros((16, 16, 3), np.uint8))
    before = _snapshot(out)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    # The command at a lower priority than this process (os.nice, then exec), so that the
    # signal lands while it renders (its 400 frames take about 1.8 s after the temporary file
    # appears, quiet): at load 15 (CI beside four other builds, 7 December) a child at this
    # process's priority once finished before this loop saw the file, and exited 0, as a run
    # whose outputs are in place does. Not preexec_fn: it forks a threaded process.
    nice = "import os, sys; os.nice(10); os.execv(sys.executable, [sys.executable, *sys.argv[1:]])"
    argv = [sys.executable, "-c", nice, "-m", "pftrack", "-q", "track", str(video), "--out",
            "t.txt", "--render", "t.mp4"]  # fmt: skip
    proc = subprocess.Popen(argv, cwd=out, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not [p for p in os.listdir(out) if p.startswith(".")]:  # rendering has started
            assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
            time.sleep(0.01)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert err.strip() == "pftrack track: terminated (SIGTERM); no output was changed"
    assert _snapshot(out) == before


def test_a_second_sigterm_does_not_break_into_the_cleanup() -> None:
    """``timeout`` sends two SIGTERMs (one to the process, one to its group). The second was
    raised again wherever the first one's cleanup stood, and could skip the wait for a live
    source's reader thread: ``pftrack track PIPE`` under ``timeout`` then ended with SIGABRT
    ("FATAL: exception not rethrown") or SIGSEGV instead of 143, about 1 run in 2. Now the
    first raises, later ones are ignored until the command ends."""
    import signal

    from pftrack.cli._signals import Terminated, sigterm_raises

    before = signal.getsignal(signal.SIGTERM)
    cleaned = False
    with pytest.raises(Terminated), sigterm_raises():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1000):  # Python runs the handler between bytecodes
                pass
        finally:
            os.kill(os.getpid(), signal.SIGTERM)  # the second, during the cleanup
            for _ in range(1000):
                pass
            cleaned = True
    assert cleaned
    assert signal.getsignal(signal.SIGTERM) == before  # restored when the command ends


def test_sigterm_ends_a_batch_with_its_own_status(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The batch says it was terminated, exit 143 (Ctrl-C: interrupted, 130)."""
    import pftrack.batch as batch
    from pftrack.cli._signals import Terminated

    def terminated(*args: Any, **kwargs: Any) -> Any:
        raise Terminated

    monkeypatch.setattr(batch, "track_many", terminated)
    assert main(["batch", str(tmp_path), "--out", str(tmp_path / "o"), "--workers", "0"]) == 143
    assert capsys.readouterr().err.startswith("pftrack batch: terminated (SIGTERM); ")


def test_no_tracks_into_a_device_or_pipe_is_an_empty_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """As a regular file gets an empty file (was: ``nothing was written for /dev/null``, 2)."""
    import threading

    video = make_scene(n_frames=3, rng=0).write_video(tmp_path / "short.avi")  # no track lives
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    for out in (tmp_path / "regular.txt", Path(os.devnull), fifo):
        assert main(["-q", "track", str(video), "--out", str(out), "--particles", "20"]) == 0
        assert "0 tracks, 0 boxes in " in capsys.readouterr().out
    reader.join(30)
    assert got == [b""] and (tmp_path / "regular.txt").read_bytes() == b""


@pytest.mark.parametrize(
    ("argv", "magic"),
    [
        ("track VIDEO --out t.txt --render OUT --plot /dev/null --particles 20", b"ftyp"),
        ("track VIDEO --out t.txt --plot OUT --render /dev/null --particles 20", b"\x89PNG"),
        ("eval --gt GT --res TRACKS --json OUT --csv /dev/null", b'{\n  "written_by"'),
        ("eval --gt GT --res TRACKS --csv OUT --json /dev/null", b"sequence,"),
        ("experiment gaps --gt WALKERS --figure OUT --json /dev/null --methods linear "
         "--repeat 1 --max-positions 1", b"\x89PNG"),
    ],
    ids=["track --render", "track --plot", "eval --json", "eval --csv", "experiment --figure"],
)  # fmt: skip
def test_a_device_or_pipe_takes_the_default_format(
    argv: str, magic: bytes, inputs: dict[str, Path], tmp_path: Path
) -> None:
    """``--render /dev/stdout`` is an MP4, ``--plot`` a PNG (was: ``unsupported extension
    '(none)'``, exit 2, though the docs said devices were accepted)."""
    import threading

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    names = {"VIDEO": inputs["video"], "GT": inputs["gt"], "TRACKS": inputs["tracks"],
             "OUT": fifo, "t.txt": tmp_path / "t.txt"}  # fmt: skip
    if "WALKERS" in argv:
        names["WALKERS"] = _walkers(tmp_path / "A")
    assert main(["-q", *(str(names.get(a, a)) for a in argv.split())]) == 0
    reader.join(60)
    assert got and magic in got[0][:16]
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def test_a_regular_file_without_extension_is_still_refused(
    inputs: dict[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str], no_work: None
) -> None:
    argv = ["track", str(inputs["video"]), "--out", str(tmp_path / "t.txt"), "--render",
            str(tmp_path / "video")]  # fmt: skip
    assert main(argv) == 2
    assert capsys.readouterr().err.endswith(
        "video: unsupported extension '(none)', expected one of .mp4, .avi\n"
    )


def test_rows_written_to_stdout_carry_no_report(tmp_path: Path) -> None:
    # was: `--out /dev/stdout` mixed the summary line (and --explain's tables) into the rows,
    # so the piped file could not be read back
    import subprocess
    import sys

    from pftrack.io.mot import read_mot
    from pftrack.synthetic import make_scene

    src = tmp_path / "t.txt"
    src.write_text("1,1,10,10,20,40\n5,1,30,10,20,40\n")
    folder = tmp_path / "img"
    make_scene(n_frames=3, width=64, height=64, n_walkers=1, rng=0).write_images(folder)
    runs = {
        "recover": ["recover", str(src), "--out", "/dev/stdout", "--explain"],
        "smooth": ["smooth", str(src), "--out", "/dev/stdout"],
        "track": ["track", str(folder), "--out", "/dev/stdout"],
        "eval": ["eval", "--gt", str(src), "--res", str(src), "--json", "/dev/stdout"],
    }
    for name, argv in runs.items():
        out = tmp_path / f"{name}.out"
        with out.open("wb") as fh:
            done = subprocess.run(
                [sys.executable, "-m", "pftrack", "-q", *argv],
                stdout=fh, stderr=subprocess.PIPE, text=True, check=False,
            )  # fmt: skip
        assert done.returncode == 0, done.stderr
        if name == "eval":
            import json

            assert json.loads(out.read_text())["mota"] == 1.0
            assert "MOTA" in done.stderr  # the table went to stderr
        else:
            read_mot(out)  # rows only: reads back
            assert str(src) in done.stderr or name == "track"


def test_names_the_terminal_cannot_encode_are_escaped(
    inputs: dict[str, Path], tmp_path: Path
) -> None:
    """``PYTHONIOENCODING=ascii pftrack recover tö.txt --out rö.txt``: was exit status 2 ("'ascii'
    codec can't encode character") after writing its output; a name's bytes that are not UTF-8
    are still written as they are (as ``ls`` does)."""
    import subprocess
    import sys

    (tmp_path / "tö.txt").write_bytes(inputs["tracks"].read_bytes())
    latin1 = os.fsdecode(b"r\xfe.txt")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path), "PYTHONIOENCODING": "ascii"}
    for out, shown in (("rö.txt", b"-> r\\xf6.txt"), (latin1, b"-> r\xfe.txt")):
        run = subprocess.run([sys.executable, "-m", "pftrack", "recover", "tö.txt", "--out", out],
                             cwd=tmp_path, capture_output=True, env=env, check=False,
                             timeout=120)  # fmt: skip
        assert run.returncode == 0 and run.stderr == b"", run.stderr
        assert shown in run.stdout and b"t\\xf6.txt" in run.stdout
        assert (tmp_path / out).stat().st_size > 0


@pytest.mark.parametrize(
    "argv",
    [["demo", "--out-dir", "-", "--frames", "5"], ["batch", "{video}", "--out", "-"],
     ["recover", "{tracks}", "{gt}", "--out", "-"], ["smooth", "{tracks}", "{gt}", "--out", "-"]],
)  # fmt: skip
def test_dash_as_an_output_folder_is_refused(
    argv: list[str],
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Was: a folder named ``-`` created and written (output files refused ``-`` already)."""
    monkeypatch.chdir(tmp_path)
    argv = [a.format(**{k: str(p) for k, p in inputs.items()}) for a in argv]
    assert main([*argv, *(["--workers", "0"] if argv[0] != "demo" else [])]) == 2
    what = "--out-dir" if argv[0] == "demo" else "--out"
    assert capsys.readouterr().err == (
        f"pftrack {argv[0]}: error: {what} -: standard output is not supported by name '-'; "
        "give a folder name\n"
    )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [["demo", "--out-dir", "{out}", "--frames", "5"], ["batch", "{video}", "--out", "{out}"],
     ["recover", "{tracks}", "{gt}", "--out", "{out}"],
     ["smooth", "{tracks}", "{gt}", "--out", "{out}"]],
)  # fmt: skip
@pytest.mark.parametrize("case", ["empty", "under a file"])
def test_an_empty_output_folder_or_one_under_a_file_is_refused(
    argv: list[str],
    case: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Was: ``--out ""`` wrote into the current folder (``Path("")`` is ``.``); a folder under a
    file: "cannot create the folder (Not a directory)"."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "notes.txt").write_text("x")
    out = "" if case == "empty" else "notes.txt/o"
    names = {k: str(p) for k, p in inputs.items()}
    argv = [a.format(out=out, **names) for a in argv]
    assert main([*argv, *(["--workers", "0"] if argv[0] != "demo" else [])]) == 2
    what = "--out-dir" if argv[0] == "demo" else "--out"
    said = (
        f"{what} is empty; give a folder name"
        if case == "empty"
        else f"{what} notes.txt/o: notes.txt is a file, not a folder"
    )
    assert capsys.readouterr().err == f"pftrack {argv[0]}: error: {said}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize(
    ("argv", "what"),
    [(["track", "-", "--out", "o.txt"], "video source"),
     (["render", "-", "{tracks}", "--out", "o.mp4"], "video source"),
     (["render", "{video}", "-", "--out", "o.mp4"], "tracks file"),
     (["recover", "-", "--out", "o.txt"], "tracks file"),
     (["smooth", "-", "--out", "o.txt"], "tracks file"),
     (["eval", "--gt", "-", "--res", "{tracks}"], "--gt"),
     (["eval", "--gt", "{gt}", "--res", "-"], "--res"),
     (["batch", "-", "--out", "o", "--workers", "0"], "input"),
     (["smooth", "-", "{tracks}", "--out", "o", "--workers", "0"], "input")],
)  # fmt: skip
def test_dash_as_an_input_says_standard_input_is_not_read(
    argv: list[str],
    what: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Was: ``tracks file not found: -``, ``video source not found: -``, as if a file was meant."""
    monkeypatch.chdir(tmp_path)
    assert main([a.format(**{k: str(p) for k, p in inputs.items()}) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pftrack {argv[0]}: error: {what} -: standard input is not ")
    assert "supported by name '-'; give a " in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_a_file_named_dash_is_still_read(
    inputs: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "-").write_bytes(inputs["tracks"].read_bytes())
    assert main(["smooth", "-", "--out", "o.txt"]) == 0
    assert (tmp_path / "o.txt").stat().st_size > 0
