"""``experiments.peer_gap_filling``: the peers' interpolations as published, and the table."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from experiments import compare_trackers
from experiments import peer_gap_filling as ex
from pftrack._typing import F64
from pftrack.io.mot import write_mot
from pftrack.synthetic import make_scene


def _track(tid: int, frames: list[int], boxes: Sequence[tuple[float, ...]]) -> F64:
    rows = np.zeros((len(frames), 10))
    rows[:, 0], rows[:, 1], rows[:, 2:6] = frames, tid, boxes
    rows[:, 6:] = (0.9, -1, -1, -1)
    return rows


def test_bytetrack_interpolation_is_a_straight_line_inside_short_holes() -> None:
    box = (10.0, 20.0, 30.0, 40.0)
    # id 1: 8 rows; a hole of 2 frames (6 -> 9) and one of 19 (9 -> 29: ends 20 apart)
    a = _track(1, [1, 2, 3, 4, 5, 6, 9, 29], [box] * 5 + [box, (16.0, 26.0, 33.0, 40.0), box])
    b = _track(2, [1, 3, 5], [box] * 3)  # 3 rows: not more than n_min = 5, left as it is
    out = ex.bytetrack_interpolation(np.vstack([a, b]), n_dti=20, n_min=5)
    assert len(out) == len(a) + len(b) + 2
    added = out[(out[:, 0] == 7) | (out[:, 0] == 8)]
    np.testing.assert_array_equal(added[:, :2], [[7, 1], [8, 1]])
    # by hand: 1/3 and 2/3 of the way from (10, 20, 30, 40) to (16, 26, 33, 40)
    np.testing.assert_allclose(added[:, 2:6], [[12, 22, 31, 40], [14, 24, 32, 40]])
    np.testing.assert_array_equal(added[:, 6:], [[1, -1, -1, -1]] * 2)
    assert np.all(np.diff(out[:, 0]) >= 0)  # sorted by frame, as dti writes them
    # n_dti = 21 fills the 19 missing frames too; n_min = 8 leaves id 1 alone
    assert len(ex.bytetrack_interpolation(a, n_dti=21)) == len(a) + 2 + 19
    assert len(ex.bytetrack_interpolation(a, n_min=8)) == len(a)


def test_strongsort_gsi_fills_then_smooths_every_row() -> None:
    rng = np.random.default_rng(0)
    frames = [f for f in range(1, 41) if not 10 <= f <= 14]  # a hole of 5 frames
    x = np.asarray(frames, float) * 2.0
    boxes = [(xi + rng.normal(), 50.0, 20.0, 40.0) for xi in x]
    rows = _track(3, frames, boxes)
    li = ex.strongsort_linear(rows, interval=20)
    assert len(li) == 40
    np.testing.assert_allclose(li[9:14, 2], li[8, 2] + (li[14, 2] - li[8, 2]) * np.arange(1, 6) / 6)
    out = ex.strongsort_gsi(rows, interval=20, tau=10.0)
    np.testing.assert_array_equal(out[:, 0], np.arange(1, 41))
    # the GP's mean by a direct solve: length clip(10 log(1000 / 40), 0.1, 100) = 32.2 frames
    t = li[:, 0]
    ls = 10.0 * np.log(1000 / 40)
    K = np.exp(-0.5 * ((t[:, None] - t[None, :]) / ls) ** 2)
    want = K @ np.linalg.solve(K + 1e-10 * np.eye(40), li[:, 2:6])
    np.testing.assert_allclose(out[:, 2:6], want, atol=1e-3)
    assert not np.allclose(out[:, 2], li[:, 2])  # observed rows are smoothed too
    assert len(ex.strongsort_gsi(rows, interval=6)) == len(rows)  # ends 6 apart: not filled


def _nearest_box_peer(seq: compare_trackers.Sequence) -> compare_trackers.Step:
    """A stand-in peer (sort-track is not among the test extras): each box takes the id of the
    last box of a track it overlaps most (IoU >= 0.3), or a new id; a track missed for a frame
    keeps its id, so its rows have holes for the variants to fill."""
    last: dict[int, F64] = {}
    ids = iter(range(1, 1_000_000))

    def iou(a: F64, b: F64) -> float:
        w = min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0])
        h = min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1])
        inter = max(w, 0.0) * max(h, 0.0)
        return inter / (a[2] * a[3] + b[2] * b[3] - inter)

    def step(frame: object, boxes: F64 | None) -> list[tuple[int, float, float, float, float]]:
        out, free = [], dict(last)
        for box in [] if boxes is None else boxes[:, :4]:
            best = max(free, key=lambda i: iou(free[i], box), default=None)
            tid = best if best is not None and iou(free[best], box) >= 0.3 else next(ids)
            free.pop(tid, None)
            last[tid] = box
            out.append((tid, *map(float, box)))
        return out

    return step


def test_table_has_every_variant_of_every_sequence_and_the_pool(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(compare_trackers.TRACKERS, "sort", _nearest_box_peer)
    scene = make_scene(n_frames=30, n_walkers=2, rng=4, occluder=False)
    folder = tmp_path / "tiny"
    folder.mkdir()
    (folder / "seqinfo.ini").write_text(
        "[Sequence]\nname=tiny\nframeRate=10\nseqLength=30\nimWidth=480\nimHeight=360\n"
    )
    write_mot(folder / "gt.txt", scene.truth)
    dets = scene.truth[(scene.truth[:, 0] % 7 != 0)].copy()  # holes for the fill
    dets[:, 1] = -1
    write_mot(folder / "det.txt", dets)
    monkeypatch.setitem(
        compare_trackers.SEQUENCES, "tiny", compare_trackers.Sequence("tiny", None, 1.0, 10.0)
    )
    monkeypatch.setitem(
        compare_trackers.SEQUENCES, "tiny2", compare_trackers.Sequence("tiny2", None, 1.0, 10.0,
                                                                      folder="tiny")
    )  # fmt: skip
    out = tmp_path / "out"
    code = ex.main(["--data", str(tmp_path), "--seq", "tiny", "tiny2", "--tracker", "sort",
                    "--out", str(out)])  # fmt: skip
    assert code == 0
    lines = (out / "peer_gap_filling.md").read_text().split("\n\n")[0].splitlines()
    body = [ln.split(" | ") for ln in lines[2:]]
    assert len(body) == 3 * len(ex.VARIANTS)  # two sequences and the pool
    assert [r[2] for r in body] == list(ex.VARIANTS) * 3
    n = len(ex.VARIANTS)
    assert [r[1] for r in body] == ["tiny"] * n + ["tiny2"] * n + ["pooled"] * n
    # the same rows twice: the pool scores as each (MOTA, IDF1, HOTA), with twice the FN
    assert [r[3:6] for r in body[2 * n :]] == [r[3:6] for r in body[:n]]
    assert [int(r[8]) for r in body[2 * n :]] == [2 * int(r[8]) for r in body[:n]]
    raw, linear = body[0], body[1]
    assert int(linear[9].rstrip(" |")) > int(raw[9].rstrip(" |"))  # the peer's holes were filled


def test_a_bad_option_is_one_line_and_status_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert ex.main(["--data", str(tmp_path), "--seq", "nope", "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith("unknown sequence 'nope'")
    assert ex.main(["--data", str(tmp_path / "none"), "--out", str(tmp_path)]) == 2
