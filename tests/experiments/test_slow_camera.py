"""experiments.slow_camera: camera motion off, auto and on along slow camera paths."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from experiments import slow_camera as sl
from experiments._common import Source
from experiments.size_check import path_affines
from pftrack.synthetic import camera_path


def test_paths_are_size_checks_and_the_moving_path_four_times_slower() -> None:
    size = (360, 480)
    for kind in sl.PATHS:
        np.testing.assert_array_equal(sl.affines_of(kind, 50, size), path_affines(kind, 50, size))
    slow = sl.affines_of("moving/4", 795, size)
    np.testing.assert_array_equal(slow, camera_path(795, size, period=480.0))
    # as docs/tracking.md gives them: every slow path under the 1.2 px threshold on PETS09's
    # 795 frames, the moving versions' own path over it
    for kind in sl.SLOW_PATHS:
        assert sl.path_motion(kind, 795, size)[1] < 1.2, kind
    assert sl.path_motion("slowpan", 795, size) == pytest.approx((0.11, 0.11), abs=0.005)
    fast = camera_path(795, size, period=120.0)
    assert np.median([np.abs(fast[k] - fast[k - 1]).max() for k in range(1, 795)]) > 1.0


# a tiny sequence the tracker matches nothing of: evaluate_sequence says so (stop 70)
@pytest.mark.filterwarnings("ignore:evaluate_sequence. none of the result's:UserWarning")
def test_run_counts_the_trackers_camera_only(data: Path) -> None:
    """Built-in detector: priming's probe is a CameraMotion of its own, not counted."""
    row = next(sl.video_rows(data, (Source("tiny", "img", 1.0),), ("slowpan",), sl.affines_of))
    frames = list(row.frames())  # type: ignore[operator]
    scores, moving = sl.run(row, frames, True, "on", 0)
    assert moving == 12 and scores.shape == (3,)
    assert sl.run(row, frames, True, "off", 0)[1] == 0
    assert sl.run(row, frames, False, "on", 0)[1] == 12


# a tiny sequence the tracker matches nothing of: evaluate_sequence says so (stop 70)
@pytest.mark.filterwarnings("ignore:evaluate_sequence. none of the result's:UserWarning")
def test_main_writes_the_table(data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    rows = sl.video_rows
    monkeypatch.setattr(
        sl, "video_rows", lambda d, **kw: rows(d, (Source("tiny", "img", 1.0),), **kw)
    )
    assert sl.main(["--data", str(data), "--out", str(tmp_path), "--seeds", "1"]) == 0
    table = (tmp_path / "slow_camera.md").read_text().splitlines()
    assert len(table) == 2 + 2 * len(sl.SLOW_PATHS)
    assert table[2].startswith("| tiny tilt | public | ")
    assert all(line.count("|") == 7 for line in table)


def test_no_video_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert sl.main(["--data", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert "no pets09-s2l1 or tud-campus video under" in capsys.readouterr().err
