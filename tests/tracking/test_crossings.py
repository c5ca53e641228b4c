"""The offline crossing repair: swapped tails exchanged back, bounces and crossings kept."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pftrack
from pftrack.boxes import iou_xywh
from pftrack.cli import build_parser, main
from pftrack.cli._options import DEFAULT_CROSSINGS, tracker_config
from pftrack.io.mot import group_by_frame, write_mot
from pftrack.synthetic import make_scene
from pftrack.tracking import CrossingConfig, TrackerConfig, repair_crossings, smooth_tracks
from pftrack.tracking.api import xywh_to_xyxy_dets
from pftrack.tracking.offline import _overlapping_pairs

ON = CrossingConfig(enabled=True)


def walkers(n=60, meet=30, bounce=False, heights=(60.0, 64.0), swap_at=None, seed=0):
    """Two walkers meeting at frame `meet`: rows ``(2n, 10)`` and each row's true person (1, 2).

    A walks right from x = 40 and B left, 4 px a frame each. They pass each other, or with
    `bounce` both turn back where they meet. With `swap_at`, the rows' ids are exchanged from
    that frame on, as a tracker that swapped them at the crossing writes them.
    """
    rng = np.random.default_rng(seed)
    f = np.arange(1, n + 1, dtype=float)
    xa = 40 + 4 * (f - 1)
    xb = 40 + 8 * (meet - 1) - 4 * (f - 1)
    if bounce:
        xa, xb = np.minimum(xa, 2 * xa[meet - 1] - xa), np.maximum(xb, 2 * xb[meet - 1] - xb)
    rows, truth = [], []
    for person, x, h, y in ((1, xa, heights[0], 100.0), (2, xb, heights[1], 106.0)):
        w = 0.4 * h
        box = np.column_stack([x - w / 2, np.full(n, y - h / 2), np.full(n, w), np.full(n, h)])
        box += rng.normal(0.0, 0.02 * h, box.shape)
        rows.append(np.column_stack([f, np.full(n, person), box, np.ones(n), -np.ones((n, 3))]))
        truth.append(np.full(n, person))
    r, t = np.vstack(rows), np.concatenate(truth)
    if swap_at is not None:
        late = r[:, 0] >= swap_at
        r[late, 1] = 3 - r[late, 1]
    return r, t


def same_person_per_id(rows, truth):
    return all(len(np.unique(truth[rows[:, 1] == i])) == 1 for i in np.unique(rows[:, 1]))


@pytest.mark.parametrize("swap_at", [27, 31, 34])
def test_a_crossing_the_tracker_swapped_is_repaired(swap_at):
    rows, truth = walkers(swap_at=swap_at)
    assert not same_person_per_id(rows, truth)  # the tracker's swap
    out = repair_crossings(rows, config=ON)
    np.testing.assert_array_equal(out[:, [0, *range(2, 10)]], rows[:, [0, *range(2, 10)]])
    late = rows[:, 0] >= max(swap_at, 31)  # after the cut (largest overlap) every row is right
    ids = {int(p): np.unique(out[late & (truth == p), 1]) for p in (1, 2)}
    assert len(ids[1]) == len(ids[2]) == 1 and ids[1][0] != ids[2][0]
    assert ids[1][0] == np.unique(out[(rows[:, 0] <= 20) & (truth == 1), 1])[0]


def test_a_crossing_tracked_right_and_a_bounce_are_kept():
    rows, truth = walkers()
    np.testing.assert_array_equal(repair_crossings(rows, config=ON), rows)
    # people who meet and turn back: motion alone says "swapped"; their sizes say they are not
    rows, truth = walkers(bounce=True, heights=(50.0, 80.0))
    assert same_person_per_id(rows, truth)
    np.testing.assert_array_equal(repair_crossings(rows, config=ON), rows)
    # without the size difference the rule cannot tell a bounce from a swap (documented)
    same, _ = walkers(bounce=True, heights=(60.0, 60.0))
    assert not np.array_equal(repair_crossings(same, config=ON), same)


def test_margin_window_and_evidence_gates():
    rows, truth = walkers(swap_at=31)
    for change in ({"margin": 1e9}, {"max_window": 2}, {"min_points": 40}):
        config = dataclasses.replace(ON, **change)
        assert np.array_equal(repair_crossings(rows, config=config), rows), change
    # only the detections are evidence: none observed, nothing judged
    none = np.zeros(len(rows), bool)
    assert np.array_equal(repair_crossings(rows, none, ON), rows)


def test_deterministic_scale_free_and_row_order_free():
    rows, _ = walkers(swap_at=31, seed=3)
    out = repair_crossings(rows, config=ON)
    assert out.tobytes() == repair_crossings(rows, config=ON).tobytes()
    big = rows.copy()
    big[:, 2:6] *= 7.0
    np.testing.assert_array_equal(repair_crossings(big, config=ON)[:, 1], out[:, 1])
    perm = np.random.default_rng(0).permutation(len(rows))
    np.testing.assert_array_equal(repair_crossings(rows[perm], config=ON)[:, 1], out[perm, 1])


def test_measurements_are_the_evidence():
    # the rows' boxes (a tracker's filtered ones) find the overlap; the detections decide
    rows, truth = walkers(swap_at=31)
    fixed = repair_crossings(rows, config=ON)
    filtered = rows.copy()
    filtered[:, 2:6] += np.random.default_rng(1).normal(0, 0.5, (len(rows), 4))
    got = repair_crossings(filtered, np.ones(len(rows), bool), ON, rows[:, 2:6])
    np.testing.assert_array_equal(got[:, 1], fixed[:, 1])


def test_off_leaves_the_offline_pass_byte_identical():
    rows, _ = walkers(swap_at=31)
    base = smooth_tracks(rows)
    assert smooth_tracks(rows, crossings=CrossingConfig()).tobytes() == base.tobytes()
    assert smooth_tracks(rows, crossings=None).tobytes() == base.tobytes()
    on = smooth_tracks(rows, crossings=ON)
    assert on.tobytes() != base.tobytes()
    np.testing.assert_array_equal(on, smooth_tracks(repair_crossings(rows, config=ON)))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"min_iou": 0.0}, "min_iou"),
        ({"join_gap": -1}, "join_gap"),
        ({"max_window": 0}, "max_window"),
        ({"min_points": 1}, "min_points"),
        ({"span": 2.5}, "span"),
        ({"accel": 0.0}, "accel"),
        ({"size_noise": float("nan")}, "size_noise"),
        ({"margin": -1.0}, "margin"),
        ({"margin": float("inf")}, "margin"),
    ],
)
def test_bad_settings(kwargs, match):
    with pytest.raises(ValueError, match=match):
        CrossingConfig(**kwargs)


def test_bad_inputs():
    rows, _ = walkers()
    with pytest.raises(ValueError, match="observed has shape"):
        repair_crossings(rows, np.ones(3, bool), ON)
    with pytest.raises(ValueError, match="measurements has shape"):
        repair_crossings(rows, None, ON, np.ones((3, 4)))
    with pytest.raises(ValueError, match="twice|duplicate|more than once"):
        repair_crossings(np.vstack([rows, rows[:1]]), config=ON)
    with pytest.raises(TypeError, match="enabled"):
        CrossingConfig(enabled="yes")  # type: ignore[arg-type]
    assert repair_crossings(np.zeros((0, 10)), config=ON).shape == (0, 10)


def test_cli_option_matches_the_config_and_the_tracker(capsys):
    assert (DEFAULT_CROSSINGS == "on") == CrossingConfig().enabled
    argv = ["track", "v.avi", "--out", "t.txt"]
    on = tracker_config(build_parser().parse_args([*argv, "--crossings", "on"]))
    enabled = dataclasses.replace(TrackerConfig().crossings, enabled=True)
    assert on == dataclasses.replace(TrackerConfig(), crossings=enabled)
    assert tracker_config(build_parser().parse_args(argv)) == pftrack.Tracker().config
    assert pftrack.Tracker(crossings=True).config == dataclasses.replace(
        pftrack.Tracker().config, crossings=enabled
    )
    with pytest.raises(SystemExit):
        main(["track", "--help"])
    assert f"(default: {DEFAULT_CROSSINGS})" in " ".join(capsys.readouterr().out.split())


def test_finalize_with_crossings_is_the_cli_byte_for_byte(tmp_path):
    scene = make_scene(n_frames=40, rng=1)
    folder = tmp_path / "seq"
    folder.mkdir()
    det_rows = []
    by_frame = group_by_frame(scene.truth)
    for n, f in enumerate(scene.frames, start=1):
        cv2.imwrite(str(folder / f"{n:06d}.png"), f)
        det_rows += [[n, -1, *r[2:6], 1.0, -1, -1, -1] for r in by_frame.get(n, [])]
    write_mot(tmp_path / "det.txt", np.asarray(det_rows))
    out = tmp_path / "t.txt"
    argv = ["-q", "track", str(folder), "--detections", str(tmp_path / "det.txt")]
    assert main([*argv, "--crossings", "on", "--out", str(out)]) == 0
    loop = pftrack.Tracker(crossings=True)
    loop.prime(scene.frames[:30])
    dets = np.asarray(det_rows)
    for n, f in enumerate(scene.frames, start=1):
        r = dets[dets[:, 0] == n]
        loop.update(xywh_to_xyxy_dets(np.column_stack([r[:, 2:6], r[:, 6]])), f)
    written = tmp_path / "loop.txt"
    write_mot(written, loop.finalize())
    assert written.read_bytes() == out.read_bytes()


def _pairs_reference(a, min_iou):
    """Frame by frame, the IoU matrix of its rows (pftrack.boxes.iou_xywh), pairs p < q."""
    out = []
    for f in np.unique(a[:, 0]):
        idx = np.flatnonzero(a[:, 0] == f)
        iou = iou_xywh(a[idx, 2:6], a[idx, 2:6])
        for u in range(len(idx)):
            for v in range(u + 1, len(idx)):
                if iou[u, v] >= min_iou:
                    out.append([f, idx[u], idx[v], iou[u, v]])
    return np.asarray(out).reshape(-1, 4)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 60), min_iou=st.sampled_from([0.01, 0.3]))
def test_overlapping_pairs_match_the_frame_by_frame_reference(seed, n, min_iou):
    rng = np.random.default_rng(seed)
    a = np.zeros((n, 10))
    a[:, 0] = np.sort(rng.integers(1, 6, n))
    a[:, 2:4] = rng.uniform(0, 50, (n, 2))
    a[:, 4:6] = rng.uniform(0, 30, (n, 2)) * (rng.random((n, 1)) > 0.1)  # some empty boxes
    np.testing.assert_array_equal(_overlapping_pairs(a, min_iou), _pairs_reference(a, min_iou))


@pytest.mark.parametrize("block", [1, 7, 100])
def test_overlapping_pairs_in_blocks_are_the_unchunked_pairs(monkeypatch, block):
    """Made PAIR_BLOCK pairs at a time (several blocks here, frames split between them): the
    rows of the unchunked computation, byte for byte, and the reference's."""
    from pftrack.tracking import offline

    rng = np.random.default_rng(block)
    n = 300
    a = np.zeros((n, 10))
    a[:, 0] = np.sort(rng.integers(1, 12, n))
    a[:, 2:4] = rng.uniform(0, 60, (n, 2))
    a[:, 4:6] = rng.uniform(0, 30, (n, 2))
    monkeypatch.setattr(offline, "PAIR_BLOCK", 1 << 40)
    whole = _overlapping_pairs(a, 0.1)
    monkeypatch.setattr(offline, "PAIR_BLOCK", block)
    got = _overlapping_pairs(a, 0.1)
    assert got.tobytes() == whole.tobytes() and len(got) > 100
    np.testing.assert_array_equal(got, _pairs_reference(a, 0.1))


def test_overlapping_pairs_are_found_in_bounded_memory():
    """repair_crossings' pairs of boxes of one frame were made all at once: 1.5 GB of
    tracemalloc peak on 2000 tracks over 3000 frames (11 million pairs), 153 MB here (1500
    boxes in one frame, 1.1 million pairs). Now PAIR_BLOCK = 2**16 at a time: 10 MB."""
    import tracemalloc

    rng = np.random.default_rng(0)
    n = 1500
    a = np.zeros((n, 10))
    a[:, 0] = 1.0
    a[:, 2:4] = rng.uniform(0, 1500, (n, 2))
    a[:, 4:6] = rng.uniform(20, 80, (n, 2))
    tracemalloc.start()
    try:
        got = _overlapping_pairs(a, 0.3)
        peak = tracemalloc.get_traced_memory()[1] / 1e6
    finally:
        tracemalloc.stop()
    assert peak < 30, f"{peak:.0f} MB"
    assert len(got) > 100


def crowd(n_tracks, seed, n_frames=120, swaps=10):
    """Walkers in a small square, many crossings; the rows' ids exchanged where random pairs of
    them overlap, from that frame on (a tracker's swaps, some chained through one id);
    detections with noise and gaps.

    Returns rows, observed, measurements.
    """
    rng = np.random.default_rng(seed)
    rows = []
    for tid in range(1, n_tracks + 1):
        n = int(rng.integers(20, 80))
        f = int(rng.integers(1, n_frames - n + 2)) + np.arange(n, dtype=float)
        p = rng.uniform(0, 300, 2) + np.outer(f - f[0], rng.normal(0, 3, 2))
        h = rng.uniform(40, 80) * (1 + 0.002 * (f - f[0]))
        box = np.column_stack([p[:, 0], p[:, 1], 0.4 * h, h])
        rows.append(np.column_stack([f, np.full(n, tid), box, np.ones(n), -np.ones((n, 3))]))
    r = np.vstack(rows)
    r = r[np.argsort(r[:, 0], kind="stable")]
    met = _overlapping_pairs(r, 0.2)
    for f, p, q, _ in met[rng.choice(len(met), swaps, replace=False)]:  # swapped where they meet
        i, j = r[int(p), 1], r[int(q), 1]
        late = r[:, 0] >= f
        ii, jj = late & (r[:, 1] == i), late & (r[:, 1] == j)
        r[ii, 1], r[jj, 1] = j, i  # a bijection of ids: still one row per (frame, id)
    r = r[rng.permutation(len(r))]
    observed = rng.random(len(r)) < 0.9
    measurements = r[:, 2:6] + rng.normal(0, 1.0, (len(r), 4))
    return r, observed, measurements


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("margin", [0.0, 5.0])
def test_repair_is_the_window_by_window_reference(seed, margin):
    """Windows judged together, index slices per track and only the exchanged ids' windows found
    again: the ids of the old loop (tests/reference/crossings.py), byte for byte. 1 to 5
    exchanges a scene; seeds 0, 1, 4 and 5 exchange one id twice (an id's windows found again
    after its first exchange decide the second)."""
    from tests.reference import crossings as reference

    rows, observed, z = crowd(30, seed)
    config = dataclasses.replace(ON, margin=margin, join_gap=seed % 3 * 3, span=10 + seed)
    got = repair_crossings(rows, observed, config, z)
    want = reference.repair_crossings(rows, observed, config, z)
    assert got.tobytes() == want.tobytes()
    assert (got[:, 1] != rows[:, 1]).any()  # exchanges made


@pytest.mark.parametrize("block", [1, 60, 1000])
def test_windows_judged_in_blocks_give_the_unchunked_ids(monkeypatch, block):
    """The Kalman scoring runs NLL_BLOCK steps times pairings at a time: one window's pairings
    may be split between blocks; the floats and ids are those of the reference's window by
    window scoring."""
    from pftrack.tracking import offline
    from tests.reference import crossings as reference

    rows, observed, z = crowd(40, block, swaps=20)
    config = dataclasses.replace(ON, margin=0.0)
    monkeypatch.setattr(offline, "NLL_BLOCK", block)
    got = repair_crossings(rows, observed, config, z)
    assert got.tobytes() == reference.repair_crossings(rows, observed, config, z).tobytes()
    assert (got[:, 1] != rows[:, 1]).sum() > 0


def test_after_nll_of_many_windows_is_each_window_alone(monkeypatch):
    from pftrack.tracking import offline
    from tests.reference import crossings as reference

    rng = np.random.default_rng(5)
    fr = np.arange(1.0, 61.0)
    cz = rng.uniform(20, 80, (60, 4))
    pairings = [
        (
            np.sort(rng.choice(30, rng.integers(2, 15), replace=False)),
            30 + np.sort(rng.choice(30, rng.integers(2, 15), replace=False)),
        )
        for _ in range(40)
    ]
    heights = rng.uniform(30, 60, 40)
    monkeypatch.setattr(offline, "NLL_BLOCK", 100)
    got = offline._after_nll(fr, cz, pairings, heights, ON)
    for k, (p, h) in enumerate(zip(pairings, heights, strict=True)):
        assert got[k] == reference.after_nll(fr, cz / h, [p], ON)[0]


def tiled_crossings(k, swap=False):
    """`k` crossings of two walkers one after another (24 frames each, no overlap between them):
    rows and windows in proportion to `k`."""
    one, _ = walkers(n=24, meet=12, swap_at=13 if swap else None)
    r = np.tile(one, (k, 1))
    c = np.repeat(np.arange(k), len(one))
    r[:, 0] += 24 * c
    r[:, 1] += 2 * c
    return r


@pytest.mark.parametrize("swap", [False, True])
def test_repair_scales_linearly_with_the_windows(swap):
    """Four times the crossings (rows and windows), about four times the CPU time. The old loop
    masked every row for each track of each window and found every window again after each
    exchange: 13.0x from 1000 to 4000 windows none judged (0.13 -> 1.66 s), 9.2x with every
    crossing swapped and repaired (1000 -> 4000: 0.50 -> 4.6 s at 40 frames a crossing); now
    3.8x and 3.6x (docs/recovery.md, "The crossing repair on large files")."""
    import time

    # none judged (too few detections): the windows' own loop; swapped: judged and exchanged
    config = ON if swap else dataclasses.replace(ON, min_points=50)
    seconds = []
    for k in (250, 1000) if swap else (1000, 4000):
        rows = tiled_crossings(k, swap)
        best = np.inf
        for _ in range(3):
            t = time.process_time()
            out = repair_crossings(rows, config=config)
            best = min(best, time.process_time() - t)
        seconds.append(best)
        assert swap == bool((out[:, 1] != rows[:, 1]).any())
    assert seconds[1] < 8 * seconds[0], seconds


def test_overlapping_pairs_score_only_boxes_sharing_columns(monkeypatch):
    """Boxes of one frame are paired only with those whose columns overlap theirs: 2000 people
    side by side in one frame, each meeting its two neighbours, make 1999 IoUs (was every pair
    of the frame: 1 999 000), and the same pairs as the frame-by-frame reference."""
    from pftrack.tracking import offline

    n = 2000
    a = np.zeros((n, 10))
    a[:, 0] = 7.0
    a[:, 1] = np.arange(1, n + 1)
    a[:, 2] = np.random.default_rng(0).permutation(n) * 30.0  # rows not in column order
    a[:, 4:6] = 40.0, 100.0
    scored = []
    iou_rows = offline._iou_rows
    monkeypatch.setattr(offline, "_iou_rows", lambda p, q: scored.append(len(p)) or iou_rows(p, q))
    got = _overlapping_pairs(a, 0.1)
    assert sum(scored) == n - 1 and len(got) == n - 1
    small = a[:200]
    np.testing.assert_array_equal(_overlapping_pairs(small, 0.1), _pairs_reference(small, 0.1))
