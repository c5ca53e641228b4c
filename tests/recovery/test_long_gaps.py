"""``auto`` on ADL-Rundle-6's gap of 182 frames: a known loss to ``linear`` (docs/recovery.md).

The bucket of 129-256 frames is validated on 12 artificial gaps cut from 2 observed runs at
starts a frame or two apart (one or two paths shifted), which rate ``gdt-mix`` far better than
``linear``; on the real gap ``gdt-mix`` errs by 57.5 px and ``linear`` by 23.3. A rule that
fills such buckets with ``linear`` (fewer than 3 validation gaps sharing no lost point) fixed
this gap but cost the perturbed copies and the files of few ids more than it gained, and was
not adopted ("Long gaps validated on one path shifted").
"""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.io.mot import read_mot
from pftrack.recovery.calibrate import recover_auto
from pftrack.recovery.experiment import find_gaps, observed_runs, trajectories
from pftrack.recovery.registry import recover_gaps

from ..conftest import dataset

MASK = (1410.0, 540.0, 250.0, 250.0)  # the first automatic mask of ADL-Rundle-6


@pytest.mark.xfail(strict=True, reason="the 12 validation gaps of 182 frames are one path shifted")
def test_auto_is_not_worse_than_linear_on_adl_rundle_6s_longest_gap() -> None:
    trajs = trajectories(read_mot(dataset("mot15-gt/ADL-Rundle-6") / "gt.txt"))
    gaps, _ = find_gaps(trajs, MASK)
    long = [k for k, g in enumerate(gaps) if len(g.truth) > 128]
    assert len(long) == 1 and len(gaps[long[0]].truth) == 182
    pairs = [(g.segment_a, g.segment_b) for g in gaps]
    auto, cal = recover_auto(pairs, observed_runs(trajs, MASK), seed=0)
    line = recover_gaps(pairs, "linear")
    g = gaps[long[0]]
    err_auto = float(np.mean(g.errors(auto[long[0]])))
    err_line = float(np.mean(g.errors(line[long[0]])))
    assert err_auto <= err_line, (err_auto, err_line, cal.describe())
