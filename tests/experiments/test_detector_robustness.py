"""experiments.detector_robustness: its --hold-frames reaches the tracker."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import pftrack.tracking
from experiments import detector_robustness


def test_hold_frames_reaches_the_tracker_and_is_printed(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seen: list[int] = []
    real = pftrack.tracking.track_frames

    def first_frames(source: Any, config: Any, **kw: Any) -> Any:
        seen.append(config.hold_frames)
        return real(source[:12], config=config, **kw)  # 12 frames are enough to run

    monkeypatch.setattr(pftrack.tracking, "track_frames", first_frames)
    for hold in (None, 7):
        args = ["--sequences", "walkers", "--variants", "ident", "--out", str(tmp_path)]
        detector_robustness.main(args + ([] if hold is None else ["--hold-frames", str(hold)]))
    assert seen == [0, 7]  # off unless asked, as TrackerConfig's default
    out = capsys.readouterr().out
    assert "hold_frames=0 " in out and "hold_frames=7 " in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--hold-frames", "-1"], "--hold-frames is -1, expected 0 (off) or more"),
        (["--hold-frames", "5", "--detector", "mog2"], "--hold-frames needs --detector paper"),
    ],
)
def test_bad_hold_frames_is_one_line(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as e:
        detector_robustness.main(["--sequences", "walkers", *args])
    assert e.value.code == 2
    assert message in capsys.readouterr().err
