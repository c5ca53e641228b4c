"""``experiments.small_files``: the small files it cuts and its table, on synthetic tracks."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from experiments import small_files as ex
from pftrack.recovery.experiment import trajectories
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def trajs() -> dict[int, np.ndarray]:
    return trajectories(make_scene(n_frames=90, n_walkers=4, rng=1).truth)


def test_pieces_are_10_to_30_rows_of_consecutive_frames(trajs: dict[int, np.ndarray]) -> None:
    out = ex._pieces(trajs, np.random.default_rng(0))
    assert len(out) > len(trajs)
    for t in out.values():
        assert 10 <= len(t) <= 30
        assert np.all(np.diff(t[:, 0]) == 1)


def test_third_keeps_every_third_frame_and_dup60_writes_each_twice(
    trajs: dict[int, np.ndarray],
) -> None:
    t = trajs[1]
    third = ex._frames({1: t}, "third")[1]
    kept = t[t[:, 0] % 3 == 1]
    np.testing.assert_array_equal(third[:, 1:], kept[:, 1:])
    np.testing.assert_array_equal(third[:, 0], (kept[:, 0] + 2) // 3)
    dup = ex._frames({1: t}, "dup60")[1]
    np.testing.assert_array_equal(dup[:, 0], np.arange(2 * t[0, 0] - 1, 2 * t[-1, 0] + 1))
    np.testing.assert_array_equal(dup[0::2, 1:], t[:, 1:])
    np.testing.assert_array_equal(dup[1::2, 1:], t[:, 1:])


def test_holes_leave_three_rows_at_each_end_and_between(trajs: dict[int, np.ndarray]) -> None:
    lost = ex._holes(trajs, np.random.default_rng(3))
    assert any(v.any() for v in lost.values())
    for tid, gone in lost.items():
        assert len(gone) == len(trajs[tid])
        assert not gone[:3].any() and not gone[-3:].any()
        kept = np.flatnonzero(~gone)
        runs = np.split(kept, np.flatnonzero(np.diff(kept) != 1) + 1)
        assert all(len(r) >= 3 for r in runs)
    gaps, runs = ex._gaps_of(trajs, lost)
    assert sum(len(r) for r in runs) == sum(int((~v).sum()) for v in lost.values())
    for g in gaps:  # each gap's truth is the rows deleted between its two segments
        assert g.segment_a[-1, 0] + 1 == g.truth[0, 0]
        assert g.truth[-1, 0] + 1 == g.segment_b[0, 0]


def test_car_case_runs_without_data_and_the_table_marks_losses(tmp_path: Path) -> None:
    res = ex.run_case("car", tmp_path, [0, 1], 0)  # no sequences there: the synthetic car only
    assert [f[0] for f in res.files] == ["car/0", "car/1"]
    n = sum(f[3] for f in res.files)
    assert len(res.errors["auto"]) == len(res.errors["linear"]) == len(res.context) == n
    text = ex.format_case("car", res)
    auto, lin = np.mean(res.errors["auto"]), np.mean(res.errors["linear"])
    first = text.splitlines()[0].split()
    assert first[:3] == ["car", "2", str(n)]
    assert first[3:5] == [f"{auto:.4g}", f"{lin:.4g}"]
    # a file worse than linear is listed, with "!" when beyond 2 standard errors
    res.files.append(("fake/9", 2.0, 1.0, 10, 0.1))
    assert "fake/9 2/1 (10)!" in ex.format_case("car", res)


def test_cases_that_draw_nothing_run_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert set(ex.FIXED_CASES) <= set(ex.CASES)
    calls: list[int] = []
    orig = ex.files

    def spy(case: str, root: Path, seed: int) -> Iterator[ex.File]:
        calls.append(seed)
        return orig(case, root, seed)

    monkeypatch.setattr(ex, "files", spy)
    ex.run_case("x10", tmp_path, [0, 1, 2], 0)
    ex.run_case("ids3", tmp_path, [0, 1, 2], 0)
    assert calls == [0, 0, 1, 2]


def test_help_shows_defaults(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as e:
        ex.main(["--help"])
    assert e.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert text.startswith("usage: python -m experiments.small_files")
    assert "case seeds (default: [0, 1, 2, 3, 4])" in text
    assert "auto's calibration seed (default: 0)" in text
