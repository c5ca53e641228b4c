"""experiments.thread_times: every thread's parts counted, the run's rows unchanged."""

from __future__ import annotations

import threading
from pathlib import Path

from experiments import thread_times
from pftrack.cli import main as pftrack_main
from pftrack.tracking.api import Tracker


def test_parts_are_counted_per_thread_and_the_rows_are_the_plain_runs(
    data: Path, tmp_path: Path
) -> None:
    source = str(data / "tiny" / "img")  # 12 frames
    update, run = Tracker.update, threading.Thread.run
    timers, wall = thread_times.measure(source, str(tmp_path / "timed.txt"))
    assert Tracker.update is update and threading.Thread.run is run  # the originals back
    roles = {t.role: t for t in timers.threads}
    main = roles["MainThread"]
    assert main.calls["Tracker.update"] == 12
    assert main.calls["Tracker.finalize (offline pass)"] == 1
    assert main.calls["wait for an item (Queue.get)"] == 13  # 12 frames and the end
    detector = roles["pftrack-prefetch (detector)"]
    assert detector.calls["detect"] == 12
    assert detector.cpu is not None and detector.wall is not None
    assert 0 < detector.seconds["detect"] <= detector.wall <= wall
    reader = roles["pftrack-prefetch (reader)"]
    assert reader.calls["camera grey"] == 12 and "detect" not in reader.calls
    text = thread_times.report(timers, wall)
    assert "pftrack-prefetch (detector), alive" in text and "12 calls  detect" in text
    assert pftrack_main(["-q", "track", source, "--out", str(tmp_path / "plain.txt")]) == 0
    assert (tmp_path / "timed.txt").read_bytes() == (tmp_path / "plain.txt").read_bytes()
