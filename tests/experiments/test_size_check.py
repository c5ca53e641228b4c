"""experiments.size_check: the fresh check set of the size-for-row rule and its decision."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from experiments import size_check as sc
from experiments._common import Source
from pftrack.io.mot import read_mot
from pftrack.io.video import FrameSource
from pftrack.synthetic import warp_frame, warp_rows
from pftrack.tracking import offline


def test_paths_tilt_pan_and_zoom_out_as_documented() -> None:
    size = (360, 480)
    tilt, pan, out = (sc.path_affines(k, 101, size) for k in sc.PATHS)
    zoomin, half, back = (sc.path_affines(k, 101, size) for k in sc.PATHS2)
    for a in (tilt, pan, out, zoomin, half, back):
        assert a.shape == (101, 2, 3)
        np.testing.assert_array_equal(a[:, 0, 1], 0.0)  # no roll
        np.testing.assert_array_equal(a[:, 1, 0], 0.0)
    centre = np.array([240.0, 180.0])

    def seen(a: np.ndarray) -> np.ndarray:
        """The source point each frame shows at the image centre."""
        return np.stack([np.linalg.solve(m[:, :2], centre - m[:, 2]) for m in a])

    np.testing.assert_allclose(tilt[:, 0, 0], 1.3)
    np.testing.assert_allclose(seen(tilt)[:, 0], 240.0)  # up and down only
    assert seen(tilt)[:, 1].max() == pytest.approx(180 + 0.06 * 360, abs=0.1)
    np.testing.assert_allclose(seen(pan)[:, 1], 180.0)  # across only, steadily
    np.testing.assert_allclose(np.diff(seen(pan)[:, 0]), 0.14 * 480 / 100)
    np.testing.assert_allclose(out[[0, -1], 0, 0], [1.5, 1.05])
    assert (np.diff(out[:, 0, 0]) < 0).all()
    np.testing.assert_allclose(seen(out), np.tile(centre, (101, 1)))  # about the centre
    # sizefit's fresh paths: zoom in, zoom out over the first half then still, pan back
    np.testing.assert_allclose(zoomin[:, 0, 0], out[::-1, 0, 0])
    np.testing.assert_allclose(half[[0, 50, 100], 0, 0], [1.5, 1.05, 1.05])
    assert (np.diff(half[:51, 0, 0]) < 0).all() and (half[50:, 0, 0] == 1.05).all()
    np.testing.assert_allclose(seen(zoomin), seen(half))
    np.testing.assert_allclose(seen(back), seen(pan)[::-1])
    with pytest.raises(ValueError, match="path is 'roll'"):
        sc.path_affines("roll", 10, size)


def test_candidates_set_size_ratio_and_turn_limit_2_and_the_guard_off_while_they_run() -> None:
    rows, spreads = offline.SIZE_ROWS, offline.SIZE_SPREADS
    assert rows is not None and spreads is not None
    with sc.candidate("off") as c:
        assert c.lifecycle.size_ratio is None
        assert (offline.SIZE_ROWS, offline.SIZE_SPREADS) == (rows, spreads)
    with sc.candidate("A") as c:
        assert c.lifecycle.size_ratio == 0.8
        assert (offline.SIZE_ROWS, offline.SIZE_SPREADS) == (rows, None)
    with sc.candidate("B") as c:
        assert c.lifecycle.size_ratio == 0.8
        assert (offline.SIZE_ROWS, offline.SIZE_SPREADS) == (None, None)
    with sc.candidate("C") as c:
        assert c.lifecycle.size_ratio == 0.8
        assert (offline.SIZE_ROWS, offline.SIZE_SPREADS) == (rows, spreads)
    assert (offline.SIZE_ROWS, offline.SIZE_SPREADS) == (rows, spreads)
    with pytest.raises(ValueError, match="candidate is 'D'"):
        with sc.candidate("D"):
            pass


def _by(off: float, a: float, b: float) -> dict[str, np.ndarray]:
    return {"off": np.full(3, off), "A": np.full(3, a), "B": np.full(3, b)}


def test_verdict_is_the_documented_rule() -> None:
    fresh = {"x auto": _by(80.0, 79.75, 80.0), "y off": _by(60.0, 60.0, 61.0)}
    public = {"p": _by(70.0, 70.0, 71.0)}
    pooled = _by(60.0, 61.0, 62.0)
    fails, chosen = sc.verdict(fresh, public, pooled)
    assert fails == {"A": [], "B": []} and chosen == "B"  # both pass: higher pooled MOTA
    fails, chosen = sc.verdict({"x auto": _by(80.0, 79.69, 80.0)}, public, pooled)
    assert fails["A"] == ["x auto: MOTA -0.31", "x auto: IDF1 -0.31", "x auto: HOTA -0.31"]
    assert chosen == "B"
    # a public sequence may not fall at all, and the pooled MOTA must rise
    fails, chosen = sc.verdict(fresh, {"p": _by(70.0, 70.0, 69.99)}, _by(60.0, 60.0, 62.0))
    assert fails["A"] == ["pooled public MOTA 60.0 not above 60.0"]
    assert fails["B"][0] == "public p: MOTA -0.01" and chosen == "off"
    assert sc.verdict(fresh, None, None)[1] == "off"  # the public sequences are part of it
    # only the candidates run are judged: off and C
    one = {k: {"off": by["off"], "C": by["B"]} for k, by in fresh.items()}
    fails, chosen = sc.verdict(one, {"p": {"off": np.full(3, 70.0), "C": np.full(3, 71.0)}},
                               {"off": np.full(3, 60.0), "C": np.full(3, 62.0)})  # fmt: skip
    assert fails == {"C": []} and chosen == "C"


def test_video_rows_move_truth_detections_and_frames_together(data: Path) -> None:
    rows = list(sc.video_rows(data, (Source("tiny", "img", 1.0),)))
    assert [r.name for r in rows] == [f"tiny {k}" for k in sc.PATHS]
    fresh = sc.video_rows(data, (Source("tiny", "img", 1.0),), sc.PATHS2, group="paths2")
    assert [(r.group, r.name) for r in fresh] == [("paths2", f"tiny {k}") for k in sc.PATHS2]
    frames = list(FrameSource(data / "tiny" / "img"))
    gt = read_mot(data / "tiny" / "gt.txt")
    for row, kind in zip(rows, sc.PATHS, strict=True):
        a = sc.path_affines(kind, 12, frames[0].shape[:2])
        assert row.n_frames == 12 and callable(row.frames)
        np.testing.assert_array_equal(row.truth, warp_rows(gt, a, frames[0].shape[:2]))
        moved = list(row.frames())
        np.testing.assert_array_equal(moved[5], warp_frame(frames[5], a[5]))
        first = row.truth[row.truth[:, 0] == 1]  # the detections are the truth, moved alike
        np.testing.assert_allclose(row.detections[1][:, :4], first[:, 2:6])


def test_main_writes_the_table_and_the_verdict(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # one small still scene whose people's sizes do not follow the row: both candidates leave
    # some of them out, and neither passes
    synthetic = sc.synthetic_rows
    monkeypatch.setattr(sc, "STILL_SCENES", (("walkers", 1),))
    monkeypatch.setattr(sc, "synthetic_rows", lambda sets: synthetic(sets, n_frames=60))
    assert sc.main(["--sets", "still", "--out", str(tmp_path)]) == 0
    text = (tmp_path / "size_check.md").read_text()
    lines = [t for t in text.splitlines() if t.startswith("| still | walkers 1 |")]
    assert len(lines) == 2  # auto and off
    assert "- chosen: off" in text and "the public sequences were not run" in text
    assert "| set | row | camera motion | off | A | B | C |" in text
    # C alone, on sizefit's still2 set (one scene): its walkers are not judged, nothing falls
    monkeypatch.setattr(sc, "STILL_SCENES2", (("walkers", 4),))
    argv = ["--sets", "still2", "--candidates", "C", "--out", str(tmp_path)]
    assert sc.main(argv) == 0
    text = (tmp_path / "size_check.md").read_text()
    lines = [t for t in text.splitlines() if t.startswith("| still2 | walkers 4 |")]
    cells = [[c.strip() for c in t.strip("|").split("|")] for t in lines]
    assert len(lines) == 2 and all(c[3] == c[4] for c in cells)
    assert "- C: fails: the public sequences were not run" in text
