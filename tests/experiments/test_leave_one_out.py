"""``experiments.leave_one_out``: each rule applied again with one sequence left out."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from experiments import leave_one_out as ex
from pftrack.eval import evaluate_sequence


def _run(rows: dict[str, tuple[float, float, float]], pooled: tuple[float, float, float],
         without: dict[str, tuple[float, float, float]]) -> dict[str, object]:  # fmt: skip
    return {"sequences": rows, "pooled": pooled, "without": without}


def _blind_coast_runs() -> dict[str, list[dict[str, object]]]:
    """Two sequences: with both, only 3 passes; without `b` (whose IDF1 2 costs 0.5), 2 too."""
    base = (50.0, 60.0, 40.0)
    runs = {v: [_run({"a": base, "b": base}, base, {"a": base, "b": base})] for v in
            ex.TRIALS["blind_coast"].values}  # fmt: skip
    up = (51.0, 61.0, 41.0)
    runs["3"] = [_run({"a": up, "b": (50.0, 60.0, 40.0)}, up, {"a": base, "b": up})]
    runs["2"] = [_run({"a": up, "b": (50.0, 59.5, 40.0)}, up, {"a": base, "b": up})]
    return runs


def test_blind_coast_rule_passes_only_what_rises_within_the_guard() -> None:
    trial = ex.TRIALS["blind_coast"]
    runs = _blind_coast_runs()
    assert ex.rule_blind_coast(runs, trial, None) == ["3"]  # 2 costs b 0.5 IDF1
    assert ex.rule_blind_coast(runs, trial, "b") == ["2", "3"]  # b left out: 2 passes too
    assert ex.rule_blind_coast(runs, trial, "a") == []  # a left out: nothing rises


def test_table_marks_a_flip_and_a_tie() -> None:
    text = ex.table({"blind_coast": {"runs": _blind_coast_runs()}})
    rows = {line.split("|")[2].strip(): line for line in text.splitlines()[2:]}
    assert "| yes |" in rows["none"]
    assert "| tied |" in rows["b"] and "| +0.0 / +0.0 / +0.0 |" in rows["b"]
    assert "nothing passes | **no** |" in rows["a"] and "+1.0 / +1.0 / +1.0" in rows["a"]


def test_relink_rule_takes_the_middle_passing_count() -> None:
    trial = ex.TRIALS["relink_coast"]
    base = (50.0, 60.0, 40.0)
    up = (50.0, 61.0, 41.0)
    runs = {
        v: [
            _run(
                {"a": up if v in ("6", "7", "8") else base},
                up if v in ("6", "7", "8") else base,
                {"a": base},
            )
        ]
        * 5  # fmt: skip
        for v in trial.values
    }
    assert ex.rule_relink_coast(runs, trial, None) == ["7"]


def test_size_ratio_rule_refuses_a_fall_on_any_sequence() -> None:
    trial = ex.TRIALS["size_ratio"]
    off, on = (50.0, 60.0, 40.0), (52.0, 60.0, 40.0)
    runs = {
        "none": [_run({"a": off, "b": off}, off, {"a": off, "b": off})] * 3,
        "0.8": [_run({"a": on, "b": (50.0, 59.9, 40.0)}, on, {"a": off, "b": on})] * 3,
    }
    assert ex.rule_size_ratio(runs, trial, None) == ["none"]  # b falls 0.1 IDF1
    assert ex.rule_size_ratio(runs, trial, "b") == ["0.8"]  # b left out: a rises, none falls
    assert ex.rule_size_ratio(runs, trial, "a") == ["none"]


def test_figures_pool_the_other_sequences() -> None:
    truth = np.array([[f, 1, 10 + f, 20, 30, 60, 1, -1, -1, -1] for f in range(1, 11)], float)
    miss = truth[::2]
    s_all, s_half = evaluate_sequence(truth, truth), evaluate_sequence(truth, miss)
    out = ex.figures(["a", "b"], [s_all, s_half])
    assert out["sequences"]["a"][0] == pytest.approx(100.0)  # type: ignore[index]
    assert out["without"]["b"] == out["sequences"]["a"]  # type: ignore[index]
    assert out["pooled"][0] == pytest.approx(75.0)  # type: ignore[index]
    with pytest.raises(ValueError, match="1 scores for 2 sequences"):
        ex.figures(["a", "b"], [s_all])


def test_table_names_an_unknown_trial_and_missing_values() -> None:
    with pytest.raises(ValueError, match="unknown trial 'nope'"):
        ex.table({"nope": {"runs": {}}})
    with pytest.raises(ValueError, match="no runs for 0, 1"):
        ex.table({"blind_coast": {"runs": {"none": []}}})


def test_cli_recomputes_the_table_and_refuses_bad_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--out", str(tmp_path)])
    assert e.value.code == 2 and "run with --measure first" in capsys.readouterr().err
    path = tmp_path / "leave_one_out.json"
    path.write_text(json.dumps({"blind_coast": {"runs": _blind_coast_runs()}}))
    assert ex.main(["--out", str(tmp_path), "--trials", "blind_coast"]) == 0
    assert "| | b | 2, 3 | tied |" in capsys.readouterr().out
    assert (tmp_path / "leave_one_out.txt").is_file()
    for bad, message in (("[1, 2]", "not a leave_one_out.json"), ("{}", "none of the trials")):
        path.write_text(bad)
        with pytest.raises(SystemExit) as e:
            ex.main(["--out", str(tmp_path)])
        err = capsys.readouterr().err
        assert e.value.code == 2 and message in err and "Traceback" not in err


def test_grid_rules_flip_where_one_scene_carried_the_choice() -> None:
    amodal = ex.GRID_RULES["amodal_share / amodal_anchor"]
    assert ex.grid_choice(amodal, None) == "0.8 side"
    assert ex.grid_choice(amodal, "tud-campus") == "0.8 centre"  # side wins on TUD alone
    ghost = ex.GRID_RULES["ghost_support (the vote)"]
    assert ex.grid_choice(ghost, None) == "0.3"
    assert ex.grid_choice(ghost, "overhead") == "ratio 0.3"  # 0.5 tops, then fails TUD
    legs = ex.GRID_RULES["leg_height / leg_fill"]
    assert ex.grid_choice(legs, "pets09-s2l1") == "0.9 / 0.2 or 1.0 / 0.2"
    shadow = ex.GRID_RULES["shadow_lo"]
    assert {ex.grid_choice(shadow, s) for s in (None, *ex.SCENES)} == {"0.5"}  # 0.8 fails


def test_recovery_rules_pool_by_gaps() -> None:
    faster = ex.SEED_RULES["real gaps faster than their validation gaps"]
    seed0 = {n: faster.before[n][0] for n in ex.REAL}
    assert ex.pool(seed0, ex.REAL) == pytest.approx(3.952, abs=5e-4)  # the docs' pooled figure
    assert ex.seed_rule_passes(faster, None) and ex.seed_rule_passes(faster, "ADL-Rundle-6")
    assert not ex.seed_rule_passes(faster, "KITTI-17")  # only KITTI-17 gains
    assert ex.threshold_choice(None) == "2 / 1 %" and ex.threshold_choice("KITTI-17") == "2 / 3 %"
    text = ex.docs_table()
    assert "KITTI-17: **not adopted**" in text and "| 2 / 1 % |" in text


def _fresh(rows: dict[str, dict[str, tuple[float, float, float]]]) -> dict[str, object]:
    """A ``fresh.json`` of min_height whose three runs give each value the same rows:
    `rows` maps a value to its two sequences' rows, pooled as their mean."""
    f = ex.FRESH["min_height"]
    figures = {}
    for v, r in rows.items():
        pool = tuple(float(np.mean([r["a"][k], r["b"][k]])) for k in range(3))
        key = "default" if v == f.default else f"{f.field}={v}"
        figures[key] = [_run(r, pool, {})] * len(ex.FRESH_RUNS)  # type: ignore[arg-type]
    return {"runs": [list(r) for r in ex.FRESH_RUNS], "figures": figures}


def test_fresh_rule_needs_a_rise_of_03_and_no_loss_beyond_the_bounds() -> None:
    f = ex.FRESH["min_height"]
    base = {"a": (50.0, 60.0, 40.0), "b": (70.0, 80.0, 60.0)}
    cases = {  # 0.67 and 0.75 against the default 0.6: the verdict on each
        "0.67": {"a": (50.6, 60.0, 40.0), "b": (70.0, 80.0, 60.0)},  # pooled MOTA +0.3: passes
        "0.75": {"a": (50.4, 60.0, 40.0), "b": (70.0, 80.0, 60.0)},  # +0.2: too little
    }
    runs = ex.fresh_runs(_fresh({"0.6": base, **cases}), "min_height")
    kept, why = ex.fresh_verdict(runs, f)
    assert kept == "0.67" and why["0.67"].startswith("passes: pooled +0.3 / +0.0 / +0.0")
    assert why["0.75"] == "fails: pooled +0.2 / +0.0 / +0.0 (none rises by 0.3)"
    # a rise of 2 MOTA that costs one sequence 0.6 MOTA (or 0.4 HOTA) is refused
    cases["0.67"] = {"a": (54.6, 60.0, 40.0), "b": (69.4, 80.0, 60.0)}
    cases["0.75"] = {"a": (51.0, 61.0, 41.0), "b": (70.0, 80.0, 59.6)}
    kept, why = ex.fresh_verdict(ex.fresh_runs(_fresh({"0.6": base, **cases}), "min_height"), f)
    assert kept == "0.6"
    assert why["0.67"] == "fails: b MOTA -0.6" and why["0.75"] == "fails: b HOTA -0.4"
    # IDF1 falling in the pool refuses it, whatever MOTA does; a loss of 0.5 MOTA is allowed
    cases["0.67"] = {"a": (52.0, 59.8, 40.0), "b": (70.0, 80.0, 60.0)}
    cases["0.75"] = {"a": (51.6, 60.0, 40.0), "b": (69.5, 80.0, 60.0)}
    kept, why = ex.fresh_verdict(ex.fresh_runs(_fresh({"0.6": base, **cases}), "min_height"), f)
    assert why["0.67"] == "fails: pooled +1.0 / -0.1 / +0.0 (one falls)" and kept == "0.75"


def test_fresh_table_reports_every_sequence_and_the_verdict(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = {"a": (50.0, 60.0, 40.0), "b": (70.0, 80.0, 60.0)}
    fresh = _fresh({"0.6": base, "0.67": base, "0.75": base})
    for name in ("birth_overlap", "relink_coast"):
        f = ex.FRESH[name]
        for v in f.candidates:
            fresh["figures"][f"{f.field}={v}"] = fresh["figures"]["default"]  # type: ignore[index]
    (tmp_path / "fresh.json").write_text(json.dumps(fresh))
    assert ex.main(["--fresh", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("held on fresh evidence") == 3 and "| a | 50.0 / 60.0 / 40.0 |" in out
    assert "| `relink_coast` | 8 | 60.0 / 70.0 / 50.0 |" in out
    assert (tmp_path / "fresh.txt").read_text() == out
    del fresh["figures"]["lifecycle.relink_coast=8"]  # type: ignore[attr-defined]
    (tmp_path / "fresh.json").write_text(json.dumps(fresh))
    with pytest.raises(SystemExit) as e:
        ex.main(["--fresh", "--out", str(tmp_path)])
    assert e.value.code == 2 and "no runs for lifecycle.relink_coast=8" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        ex.main(["--fresh", "--out", str(tmp_path / "none")])
    assert e.value.code == 2 and "run with --fresh --measure first" in capsys.readouterr().err
    for bad in ("[1]", "{"):
        (tmp_path / "fresh.json").write_text(bad)
        with pytest.raises(SystemExit) as e:
            ex.main(["--fresh", "--out", str(tmp_path)])
        err = capsys.readouterr().err
        assert e.value.code == 2 and "not a fresh.json" in err and "Traceback" not in err
