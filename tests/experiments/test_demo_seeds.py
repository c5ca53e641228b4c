"""``experiments.demo_seeds``: its seed lists, its refusals, and one scene's row."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments import demo_seeds as ex


def test_seed_range_reads_ranges_and_lists() -> None:
    assert ex.seed_range("0-3") == [0, 1, 2, 3]
    assert ex.seed_range("2,7, 9-10,") == [2, 7, 9, 10]
    with pytest.raises(ValueError, match="'x-2' is not N or N-M"):
        ex.seed_range("x-2")


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--kinds", "walkers,crowd"], "unknown kind(s): crowd"),
        (["--seeds", "1-b"], "'1-b' is not N or N-M"),
    ],
)
def test_bad_options_exit_2_with_one_line(
    argv: list[str], said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main([*argv, "--out", str(tmp_path)])
    assert e.value.code == 2
    assert said in capsys.readouterr().err
    assert not any(tmp_path.iterdir())  # refused before any work


def test_one_scene_is_tracked_scored_and_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The demo's scene of seed 1 (150 frames, five walkers): one row, the kind's mean and
    worst, and the same row in the JSON file."""
    assert ex.main(["--kinds", "walkers", "--seeds", "1", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    rows = json.loads((tmp_path / "demo_seeds.json").read_text())
    assert [(r["scene"], r["seed"]) for r in rows] == [("walkers", 1)]
    row = rows[0]
    assert -100.0 <= row["mota"] <= 100.0 and 0.0 <= row["hota"] <= 100.0
    assert f"walkers     1 {row['hota']:6.1f} {row['mota']:6.1f}" in out
    assert f"walkers    1  {row['hota']:5.1f}" in out  # the summary line, n = 1
    assert (tmp_path / "demo_seeds.txt").read_text().startswith("tracker seed 0")
