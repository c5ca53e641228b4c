"""Every command checks its outputs before any work, fails in one line, and never loses a file.

The cases (one parametrised row each) are the table of docs/robustness.md: for each command,
an output that is a folder, in a missing folder, in an unwritable folder, with an unsupported
extension, or naming an input; each must end in ``pftrack CMD: error: ...`` on one line, exit
status 2, with the existing outputs byte for byte as they were and no stray temporary file.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import write_mot
from pftrack.synthetic import make_scene

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
Builder = Callable[[dict[str, Path], Path, Path], list[str]]
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


def _bad_output(case: str, command: str, inputs: dict[str, Path], tmp: Path) -> Path:
    name = GOOD_NAME.get(command, "out.txt")
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
    if case == "an input":
        key = "gt" if command == "eval --json" else "tracks"
        if command.startswith("track"):
            key = "video"
        if command in GOOD_NAME:
            pytest.skip("its extension check comes first (covered above)")
        return inputs[key]
    raise AssertionError(case)


CASES = ["existing folder", "missing folder", "unwritable folder", "unsupported extension",
         "an input"]  # fmt: skip


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    return {p.name: (p.read_bytes() if p.is_file() else None) for p in folder.iterdir()}


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("command", list(COMMANDS))
def test_bad_output_is_refused_before_any_work(
    command: str,
    case: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import pftrack.tracking as tracking

    def no_work(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("work started before the outputs were checked")

    monkeypatch.setattr(tracking, "track_frames", no_work)
    (tmp_path / "t_ok.txt").write_text("old tracks\n")
    out = _bad_output(case, command, inputs, tmp_path)
    before_inputs = {k: p.read_bytes() for k, p in inputs.items()}
    before = _snapshot(tmp_path)
    assert main(COMMANDS[command](inputs, out, tmp_path)) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pftrack {command.split()[0]}: error: "), err
    assert _snapshot(tmp_path) == before  # nothing changed, nothing left behind
    assert {k: p.read_bytes() for k, p in inputs.items()} == before_inputs


def test_demo_refuses_a_file_as_its_folder_and_a_folder_as_an_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["demo", "--out-dir", str(f), "--frames", "5"]) == 2
    assert capsys.readouterr().err.startswith("pftrack demo: error: --out-dir")
    (tmp_path / "d" / "annotated.mp4").mkdir(parents=True)
    assert main(["demo", "--out-dir", str(tmp_path / "d"), "--frames", "5"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pftrack demo: error: ") and "is a folder" in err
    assert sorted(p.name for p in (tmp_path / "d").iterdir()) == ["annotated.mp4"]


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
    for p in (out, video, plot):
        p.write_bytes(b"good result of an earlier run\n")
    real_track = tracking.track_frames

    def interrupt_after_writing(path: Any, *args: Any, **kwargs: Any) -> None:
        Path(path).write_bytes(b"half a file")
        raise KeyboardInterrupt

    def interrupt_mid_video(source: Any, *args: Any, **kwargs: Any) -> Any:
        def frames() -> Any:
            for k, frame in enumerate(source):
                if k == 10:
                    raise KeyboardInterrupt
                yield frame

        return real_track(frames(), *args, **kwargs)

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
