"""Temporary files a killed run left are said by the next run into the folder (stop 74's trial).

Ctrl-C and SIGTERM remove a run's temporary files; ``kill -9`` (the out-of-memory killer, a
CI timeout, a power cut) cannot. A ``pftrack track --render`` killed 4 s into PETS09 left
``.r.<hex>.mp4`` and ``..r.<hex>.<hex>.mp4`` (6 MB) beside its outputs, and a later run into
the folder left them there without a word. Now the first write of a run into a folder says
each hidden temporary unwritten for 10 minutes or more, in one line, and leaves it; a fresh
one (a run still writing) and the online rows a live run keeps on purpose (``.part``) are not
said.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pftrack.cli import main
from pftrack.synthetic import make_scene

SAID = "is a partial file of a pftrack run that stopped writing it"


@pytest.fixture(scope="module")
def video(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_scene(n_frames=150, rng=1).write_video(tmp_path_factory.mktemp("v") / "v.avi")


def track(video: Path, out: Path) -> str:
    """``pftrack track VIDEO --out OUT``'s stderr, in a process of its own (exit 0 asserted)."""
    run = subprocess.run(
        [sys.executable, "-m", "pftrack", "-q", "track", str(video), "--out", str(out)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    return run.stderr


def hidden(folder: Path) -> list[str]:
    return sorted(name for name in os.listdir(folder) if name.startswith("."))


@pytest.mark.skipif(sys.platform == "win32", reason="kill -9 is POSIX's")
def test_a_killed_render_leaves_temporaries_that_the_next_run_says(
    video: Path, tmp_path: Path
) -> None:
    out = tmp_path / "out"
    out.mkdir()
    run = subprocess.Popen(
        [sys.executable, "-m", "pftrack", "-q", "track", str(video), "--out",
         str(out / "t.txt"), "--render", str(out / "r.mp4")],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not any(n.endswith(".mp4") for n in hidden(out)) and run.poll() is None:
            assert time.monotonic() < deadline, "no temporary video appeared"
            time.sleep(0.02)
        run.send_signal(signal.SIGKILL)
    finally:
        run.wait()
    left = hidden(out)
    if run.returncode != -signal.SIGKILL or not left:  # pragma: no cover - finished first
        pytest.skip("the run ended before it was killed")
    assert all(name.startswith((".r.", "..r.")) for name in left), left
    # just killed: a run still writing looks the same, so nothing is said yet (each run a
    # process of its own, as a user's: a process looks at a folder once)
    assert SAID not in track(video, out / "a.txt")
    old = time.time() - 2 * 3600
    for name in left:
        os.utime(out / name, (old, old))
    said = [line for line in track(video, out / "b.txt").splitlines() if SAID in line]
    assert said == [
        f"pftrack track: warning: {out / name} {SAID} 2 h ago (killed: kill -9, out of memory, "
        "a power cut) and left it; nothing reads it: delete it, unless a run that is still "
        "going (paused?) writes there"
        for name in left
    ]
    assert hidden(out) == left  # said, not removed


@pytest.mark.filterwarnings("always::UserWarning")
def test_only_pftracks_stale_temporaries_are_said(
    video: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    old = time.time() - 20 * 60
    names = {
        ".t.txt.0123456789ab.tmp": True,  # atomic_write's
        ".plot.0123456789ab.png": True,  # staged_outputs'
        ".t.txt.0123456789ab.probe": True,  # the output check's
        ".t.txt.0123456789ab.part": False,  # a live run's rows, kept on purpose
        ".t.txt.0123456789ab.old": False,  # a backup: said in its own words
        ".hidden": False,  # the user's
        ".notes.txt": False,
        ".x.0123456789.mp4": False,  # 10 digits: not a token of pftrack's
    }
    for name in names:
        (tmp_path / name).write_bytes(b"")
        os.utime(tmp_path / name, (old, old))
    (tmp_path / ".fresh.0123456789ab.mp4").write_bytes(b"")  # written just now: a live run's
    assert main(["-q", "track", str(video), "--out", str(tmp_path / "t.txt")]) == 0
    err = capsys.readouterr().err
    said = sorted(n for n in [*names, ".fresh.0123456789ab.mp4"] if f"{tmp_path / n} {SAID}" in err)
    assert said == sorted(n for n, s in names.items() if s)
    assert f"{SAID} 20 min ago" in err
