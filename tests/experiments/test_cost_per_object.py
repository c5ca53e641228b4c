"""The cost-per-object experiment: its crowd, the per-object loop it compares with, its files."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from experiments import cost_per_object as exp


def test_crowd_is_seeded_and_every_walker_in_view():
    frames, dets = exp.make_crowd(12, 5, (320, 240), seed=3)
    again, dets2 = exp.make_crowd(12, 5, (320, 240), seed=3)
    assert len(frames) == len(dets) == 5
    assert all(np.array_equal(a, b) for a, b in zip(frames, again, strict=True))
    for d in dets:
        assert d.shape == (12, 5)
        assert np.all(d[:, 0] >= 0) and np.all(d[:, 2] <= 320)
        assert np.all(d[:, 1] >= 0) and np.all(d[:, 3] <= 240)
    assert not np.array_equal(dets[0], dets[4])  # they walk
    with pytest.raises(ValueError, match="n_objects"):
        exp.make_crowd(0, 5)


def test_per_object_loop_gives_the_same_tracks():
    frames, dets = exp.make_crowd(6, 12, (320, 240), seed=1)

    def run() -> list[np.ndarray]:
        tracker = exp.new_tracker()
        return [tracker.update(d, f) for d, f in zip(dets, frames, strict=True)]

    batched = run()
    with exp.per_object_loop():
        single = run()
    assert sum(len(o) for o in batched) > 0
    for a, b in zip(batched, single, strict=True):
        np.testing.assert_array_equal(a, b)


def test_main_writes_table_csv_and_plot(tmp_path: Path):
    def fake(counts):
        return [
            {k: float(n) * (1 + i) for i, k in enumerate(exp_keys)} | {"objects": float(n)}
            for n in counts
        ]

    exp_keys = ["batched_wall", "batched_cpu", "per_object_wall", "per_object_cpu",
                "no_refine_wall", "no_refine_cpu"]  # fmt: skip
    exp.main(["--out", str(tmp_path), "--counts", "1,5,9"], measure_fn=fake)
    md = (tmp_path / "cost_per_object.md").read_text()
    assert md.count("\n| ") == 3 and "per object" in md
    assert "+ 2000.0 µs per object" in md  # batched_cpu = 2 n: a line through the origin
    assert (tmp_path / "cost_per_object.csv").read_text().count("\n") == 4
    img = cv2.imread(str(tmp_path / "cost_per_object.png"))
    assert img is not None and img.shape == (560, 900, 3) and img.std() > 10
    with pytest.raises(SystemExit):
        exp.main(["--out", str(tmp_path), "--counts", "a,b"], measure_fn=fake)
