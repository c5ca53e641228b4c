"""experiments.detector_robustness: its --hold-frames and grey settings reach the tracker."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import pftrack.tracking
from experiments import detector_robustness


@pytest.fixture
def configs(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The config of each ``track_frames`` call the experiment makes, on 12 frames of each."""
    seen: list[Any] = []
    real = pftrack.tracking.track_frames

    def first_frames(source: Any, config: Any, **kw: Any) -> Any:
        seen.append(config)
        return real(source[:12], config=config, **kw)  # 12 frames are enough to run

    monkeypatch.setattr(pftrack.tracking, "track_frames", first_frames)
    return seen


def test_hold_frames_reaches_the_tracker_and_is_printed(
    configs: list[Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for hold in (None, 7):
        args = ["--sequences", "walkers", "--variants", "ident", "--out", str(tmp_path)]
        detector_robustness.main(args + ([] if hold is None else ["--hold-frames", str(hold)]))
    seen = [c.hold_frames for c in configs]
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


def test_grey_settings_reach_the_detector_and_are_printed(
    configs: list[Any], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["--sequences", "walkers", "--variants", "ident", "--out", str(tmp_path)]
    detector_robustness.main(args)
    detector_robustness.main([*args, "--grey-t-min", "20", "--grey-shadow-lo", "0.8"])
    seen = [c.detector for c in configs]
    assert seen[0] == "paper"  # unchanged unless asked
    assert (seen[1].grey_t_min, seen[1].grey_shadow_lo, seen[1].t_min) == (20.0, 0.8, 25.0)
    assert "detector=paper grey_t_min=20 grey_shadow_lo=0.8 " in capsys.readouterr().out
    detector_robustness.main([*args, "--grey-texture", "0.7", "--grey-texture-erode", "3"])
    seen = [c.detector for c in configs]
    assert (seen[2].grey_texture, seen[2].grey_texture_erode) == (0.7, 3)
    assert "detector=paper grey_texture=0.7 grey_texture_erode=3 " in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--grey-t-min", "70"], "grey_t_min is 70.0, expected None or in [0, t_max]"),
        (["--grey-shadow-lo", "2"], "grey_shadow_lo is 2.0, expected in [0, 1]"),
        (["--grey-t-min", "9", "--detector", "knn"], "--grey-t-min, --grey-shadow-lo and --grey"),
        (["--grey-texture", "2"], "grey_texture is 2.0, expected in [0, 1] (0: off)"),
        (["--grey-texture-window", "4"], "grey_texture_window is 4, expected an odd number"),
    ],
)
def test_bad_grey_settings_are_one_line(
    args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as e:
        detector_robustness.main(["--sequences", "walkers", *args])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
