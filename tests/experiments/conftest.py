"""Fixtures shared by the experiments' tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from pftrack.io.mot import write_mot
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def data(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A data folder with one short sequence laid out like the real ones: ``tiny/img`` (12
    PNG frames, two walkers), ``tiny/gt.txt`` and ``tiny/det.txt`` (the truth, ids -1)."""
    root = tmp_path_factory.mktemp("data")
    scene = make_scene(n_frames=12, n_walkers=2, rng=4, occluder=False)
    folder = root / "tiny"
    folder.mkdir()
    scene.write_images(folder / "img", ext=".png")
    write_mot(folder / "gt.txt", scene.truth)
    dets = scene.truth.copy()
    dets[:, 1] = -1
    write_mot(folder / "det.txt", dets)
    return root
