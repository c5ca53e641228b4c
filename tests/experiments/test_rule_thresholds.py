"""``experiments.rule_thresholds``: the rule's thresholds set and restored, the distinct
sequences, the table; on a tiny synthetic scene."""

from __future__ import annotations

import numpy as np
import pytest

from experiments import rule_thresholds as ex
from pftrack.recovery import calibrate
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def srcs() -> list[ex.Source]:
    scene = make_scene(n_frames=60, n_walkers=4, rng=2)
    return [("tiny", scene.truth, 480.0, 360.0, scene.fps)]


def test_rule_sets_the_thresholds_and_restores_them() -> None:
    before = calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN
    with ex.rule(9.0, 0.5):
        assert (calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN) == (9.0, 0.5)
    assert (calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN) == before
    with pytest.raises(KeyError), ex.rule(7.0, 0.2):
        raise KeyError("in the block")
    assert (calibrate.PAIRED_Z, calibrate.LINEAR_MARGIN) == before


def test_each_distinct_sequence_once() -> None:
    got = ex.variants([4, 5])
    assert got[0] == ("none", 4)
    assert [v for v in got if v[0] in ex.UNSEEDED] == [("pan", 4), ("halffps", 4)]
    assert [v for v in got if v[0] == "shake"] == [("shake", 4), ("shake", 5)]
    assert len(got) == len(set(got)) == 1 + 2 + 2 * 2


def test_score_and_table(srcs: list[ex.Source]) -> None:
    strict = ex.score(srcs, 1e9, 0.99, [0])  # nothing can win: auto is the straight line
    assert [r.name for r in strict] == [
        "tiny", "tiny-pan", "tiny-shake-s0", "tiny-halffps", "tiny-jitter-s0",
    ]  # fmt: skip
    assert all(r.n_gaps > 0 for r in strict)
    for r in strict:
        np.testing.assert_allclose(r.auto, r.linear, rtol=1e-9)
    usual = ex.score(srcs, 2.0, 0.01, [0])
    assert [r.linear for r in usual] == [r.linear for r in strict]  # linear ignores the rule
    text = ex.format_table({(2.0, 0.01): usual, (1e9, 0.99): strict})
    lines = text.splitlines()
    assert lines[1].split()[:3] == ["2", "0.01", f"{usual[0].auto:.3f}"]
    worse = [r for r in usual if r.auto > r.linear]
    assert lines[1].split()[-1] == str(len(worse))
    assert lines[-2].startswith("Z=2 margin=0.01: worse than linear on ")
    assert all(r.name in lines[-2] for r in worse)
    assert lines[3].split()[:2] == ["linear", f"{usual[0].linear:.3f}"]


def test_help_and_bad_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--help"])
    assert e.value.code == 0
    assert "(default: 0.01 0.03 0.05)" in " ".join(capsys.readouterr().out.split())
    with pytest.raises(SystemExit) as e:
        ex.main(["--margin", "1.5"])
    assert e.value.code == 2
    assert "--margin in [0, 1)" in capsys.readouterr().err
