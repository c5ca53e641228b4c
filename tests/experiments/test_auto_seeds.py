"""``experiments.auto_seeds`` on a tiny synthetic scene."""

from __future__ import annotations

import numpy as np

from experiments import auto_seeds as ex
from pftrack.recovery import recover_gaps
from pftrack.recovery.experiment import auto_masks, find_gaps, observed_runs, trajectories
from pftrack.synthetic import make_scene


def test_seed_row_and_table() -> None:
    trajs = trajectories(make_scene(n_frames=80, n_walkers=5, rng=3).truth)
    row = ex.seed_row("tiny", trajs, 480.0, 360.0, [0, 1], fixed=("linear", "rts"))
    assert row.n_gaps > 0 and len(row.auto) == 2 and np.all(np.isfinite(row.auto))
    # seed 0 is what the protocol's "auto" (recover_gaps, seed 0) gives
    errs = []
    for mk in auto_masks(trajs, 480.0, 360.0, 3):
        gaps, _ = find_gaps(trajs, mk)
        pairs = [(g.segment_a, g.segment_b) for g in gaps]
        paths = recover_gaps(pairs, "auto", observed=observed_runs(trajs, mk))
        errs += [
            np.mean(np.hypot(*(p - g.truth[:, 1:3]).T)) for g, p in zip(gaps, paths, strict=True)
        ]
    assert row.auto[0] == float(np.mean(errs))
    assert row.best[0] in ("linear", "rts")
    text = ex.format_rows([row], [0, 1], ["tiny"])
    assert "tiny" in text and "seed 1:" in text
    pooled = [ln for ln in text.splitlines() if ln.startswith("pooled")]
    assert len(pooled) == 1 and f"{row.auto[1]:.3f}" in pooled[0]  # one sequence: its own row
