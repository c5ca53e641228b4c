"""experiments.crowd_split: the detector's coverage counts and the usage errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from experiments import crowd_split
from pftrack.detection import crowd, paper
from pftrack.synthetic import make_scene


def test_coverage_counts_every_truth_box_once_and_leaves_the_detector_as_it_was(
    tmp_path: Path,
) -> None:
    crowd_split.main(["--seqs", "walkers:0", "--coverage", "--out", str(tmp_path)])
    rows = [json.loads(line) for line in (tmp_path / "crowd_split.jsonl").read_text().splitlines()]
    assert [r["variant"] for r in rows] == ["base", "split"]
    truth = len(make_scene(n_frames=150, rng=0).truth)
    for r in rows:
        assert r["tp"] + r["fn_merged"] + r["fn_part"] + r["fn_lost"] == truth
    assert rows[0]["split_ms"] == 0.0  # off: never called
    assert paper.split_crowds is crowd.split_crowds  # the timing wrapper is removed


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--seqs", "walkers"], "'walkers' is not pets, tud, crowd:N:S or KIND:SEED"),
        (["--seqs", "crowd:48"], "'crowd:48' is not"),
        (["--seqs", "pets", "--variants", "both"], "--variants: 'both'"),
    ],
)
def test_bad_usage_is_one_line_and_status_2(
    args: list[str], said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as e:
        crowd_split.main([*args, "--out", str(tmp_path)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err
