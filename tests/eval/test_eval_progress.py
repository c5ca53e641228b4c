"""``pftrack eval``'s bar counts frames as a sequence is scored; the scores stay the same."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import numpy as np
import pytest

from pftrack import _progress
from pftrack._progress import REPORTS, reporting
from pftrack.cli import main
from pftrack.eval import evaluate_hota, evaluate_mot, evaluate_sequence
from tests.eval.cases import perturbed, write_rows


def long_case(n_frames: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Three walkers over `n_frames` frames (one leaves half-way), and a tracker's result."""
    rng = np.random.default_rng(seed)
    rows = []
    for oid in range(1, 4):
        last = n_frames if oid < 3 else n_frames // 2
        f = np.arange(1, last + 1, dtype=float)
        x = 20.0 + 60 * oid + np.cumsum(rng.normal(0, 0.5, len(f)))
        box = np.tile([50.0, 30.0, 70.0, 1.0, -1.0, -1.0, -1.0], (len(f), 1))  # top, w, h, ...
        rows.append(np.column_stack([f, np.full(len(f), oid), x, box]))
    gt = np.concatenate(rows)
    gt = gt[np.argsort(gt[:, 0], kind="stable")]
    return gt, perturbed(gt, seed)


def on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> tuple[io.StringIO, list[int]]:
    """stderr a terminal, bars drawn at once; the counts the bars are set to.

    Called in the test itself: capsys puts its own stderr in place as the test starts.
    """
    err = io.StringIO()
    err.isatty = lambda: True  # type: ignore[method-assign]
    monkeypatch.setattr(sys, "stderr", err)
    monkeypatch.setattr(_progress, "_quiet", False)
    monkeypatch.setattr(_progress, "DELAY", 0.0)
    seen: list[int] = []
    real_set = _progress.Bar.set
    monkeypatch.setattr(_progress.Bar, "set", lambda bar, n: (seen.append(n), real_set(bar, n)))
    return err, seen


def test_the_bar_counts_the_frames_of_one_long_sequence_as_it_is_scored(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was a bar of sequences: one sequence of 100 000 frames sat at 0/1 for its 37 s, with no
    time left. Now the frames of the sequence (of its ground truth or result), moved as its
    scorers go through them."""
    err, seen = on_a_terminal(monkeypatch)
    gt, res = long_case(3000)
    argv = ["eval", "--gt", str(write_rows(tmp_path / "gt.txt", gt))]
    argv += ["--res", str(write_rows(tmp_path / "res.txt", res))]
    assert main(argv) == 0
    table = capsys.readouterr().out
    n = len(np.union1d(gt[:, 0], res[:, 0]))
    assert seen[-1] == n and seen == sorted(seen)
    inside = {k for k in seen if 0 < k < n}
    assert len(inside) > 20, seen  # it moves within the sequence, not only at its end
    assert f"{n}/{n}" in err.getvalue() and "frame/s" in err.getvalue()
    # the same table as without a bar
    seen.clear()
    assert main(["-q", *argv]) == 0
    assert capsys.readouterr().out == table and not seen


def test_reading_and_checking_the_files_is_a_first_stage_on_the_bar(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: nothing drawn while the files were read and checked, 5 s of a pair of 100 000
    frames (reading 2 s, the scale check 3 s) before the frames' bar appeared. Now a bar of
    the files, each counted once read and checked; the table is the same."""
    import pftrack.io.mot as mot

    err, seen = on_a_terminal(monkeypatch)
    stages: list[tuple[int | None, str, str]] = []
    real_init = _progress.Bar.__init__

    def init(bar: _progress.Bar, total: int | None, **kwargs: object) -> None:
        stages.append((total, str(kwargs.get("desc")), str(kwargs.get("unit"))))
        real_init(bar, total, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(_progress.Bar, "__init__", init)
    read: list[int] = []  # how many counts the bar had as each file was read
    real = mot.read_mot  # eval imports it when it runs: the spy is what it gets

    def spy(path: object, **kwargs: object) -> object:
        read.append(len(seen))
        return real(path, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(mot, "read_mot", spy)
    cases = {"A": long_case(400, 1), "B": long_case(600, 2)}
    for name, (gt, res) in cases.items():
        write_rows(tmp_path / "gt" / name / "gt" / "gt.txt", gt)
        write_rows(tmp_path / "res" / f"{name}.txt", res)
    argv = ["eval", "--gt", str(tmp_path / "gt"), "--res", str(tmp_path / "res")]
    assert main(argv) == 0
    table = capsys.readouterr().out
    assert stages[0] == (4, "eval reading", "file")  # before the frames' bar
    assert stages[1][2] == "frame"
    assert seen[:4] == [1, 2, 3, 4]  # one count per file, the result's once checked
    assert read == [0, 1, 2, 3]  # each file read before it is counted
    assert "eval reading: 100%" in err.getvalue() and "4/4" in err.getvalue()
    seen.clear()
    assert main(["-q", *argv]) == 0
    assert capsys.readouterr().out == table and not seen


def test_the_bar_counts_every_sequence_of_a_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    err, seen = on_a_terminal(monkeypatch)
    cases = {"A": long_case(400, 1), "B": long_case(600, 2)}
    for name, (gt, res) in cases.items():
        write_rows(tmp_path / "gt" / name / "gt" / "gt.txt", gt)
        write_rows(tmp_path / "res" / f"{name}.txt", res)
    assert main(["eval", "--gt", str(tmp_path / "gt"), "--res", str(tmp_path / "res")]) == 0
    assert "COMBINED" in capsys.readouterr().out
    counts = [len(np.union1d(g[:, 0], r[:, 0])) for g, r in cases.values()]
    assert seen[-1] == sum(counts) and seen == sorted(seen)
    assert counts[0] in seen  # the first sequence done, then the second's frames on top
    assert "eval 2/2 sequences" in err.getvalue()


def test_no_bar_no_reports_off_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Off a terminal nothing is drawn, and the scorers are given nobody to report to."""
    monkeypatch.setattr(_progress, "_quiet", False)
    monkeypatch.setattr(_progress, "DELAY", 0.0)
    import pftrack.eval.sequences as sequences

    given: list[object] = []
    real = sequences.evaluate_sequence

    def spy(*args: object, **kwargs: object) -> object:
        given.append(kwargs.get("on_progress"))
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(sequences, "evaluate_sequence", spy)
    gt, res = long_case(200)
    argv = ["eval", "--gt", str(write_rows(tmp_path / "gt.txt", gt))]
    assert main([*argv, "--res", str(write_rows(tmp_path / "res.txt", res))]) == 0
    assert given == [None]
    out, err = capsys.readouterr()  # capsys's stderr: no terminal
    assert "HOTA" in out and err == ""


@pytest.mark.parametrize("fn", [evaluate_sequence, evaluate_hota, evaluate_mot])
def test_on_progress_goes_from_0_to_1_and_changes_no_score(fn: object) -> None:
    gt, res = long_case(2000, 3)
    told: list[float] = []
    with_bar = fn(gt, res, on_progress=told.append)  # type: ignore[operator]
    alone = fn(gt, res)  # type: ignore[operator]
    assert repr(with_bar.as_dict()) == repr(alone.as_dict())  # every bit, NaN too
    assert told[-1] == 1.0 and told == sorted(told) and 0 < told[0] < 1
    assert len(told) <= 6 * REPORTS  # a few hundred calls, not one per frame
    assert len(set(told)) > 50


@pytest.mark.parametrize("fn", [evaluate_sequence, evaluate_hota, evaluate_mot])
def test_on_progress_that_is_not_callable_is_refused_first(fn: object) -> None:
    gt, res = long_case(10)
    name = fn.__name__  # type: ignore[attr-defined]
    with pytest.raises(TypeError, match=f"^{name}: on_progress is float, expected a callable"):
        fn(gt, res, on_progress=0.5)  # type: ignore[operator]


def test_on_progress_of_nothing_to_score_ends_at_1() -> None:
    gt, _ = long_case(10)
    told: list[float] = []
    evaluate_sequence(gt, np.zeros((0, 10)), on_progress=told.append)
    assert told[-1] == 1.0 and told == sorted(told)


def test_reporting_reports_a_bounded_number_of_times() -> None:
    items = list(range(10 * REPORTS + 7))
    told: list[float] = []
    assert list(reporting(items, told.append, 0.2, 0.6)) == items
    assert len(told) < 2 * REPORTS and told[-1] == 0.6 and told == sorted(told)
    assert told[0] == pytest.approx(0.2 + 0.4 * 10 / len(items))
    assert reporting(items, None) is items  # nobody to tell: the items as they are
    told.clear()
    assert list(reporting([7], told.append)) == [7] and told == [1.0]
