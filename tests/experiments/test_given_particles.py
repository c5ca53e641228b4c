"""The particle-count experiment (``python -m experiments.given_particles``) on a tiny sequence."""

from __future__ import annotations

from pathlib import Path

import pytest

from experiments import given_particles as gp
from experiments._common import Source


def test_scores_are_seeded_and_in_percent(data: Path) -> None:
    a = gp.scores(data / "tiny", "img", 1.0, 20, 0)
    assert a == gp.scores(data / "tiny", "img", 1.0, 20, 0)
    assert all(-100.0 <= v <= 100.0 for v in a) and a[1] > 50.0  # the truth as detections


def test_main_prints_every_seed_and_the_means(
    data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(gp, "PETS", Source("tiny", "img", 1.0))
    monkeypatch.setattr(gp, "TUD", Source("absent", "video.mp4", 1.0))
    out = tmp_path / "out"
    args = ["--data", str(data), "--out", str(out), "--seeds", "2", "--counts", "10", "20"]
    assert gp.main(args) == 0
    text = (out / "given_particles.txt").read_text()
    assert text.count("tiny particles   10 seed") == 2 and text.count("MEAN over 2 seeds") == 2
    assert "absent: not found" in text
