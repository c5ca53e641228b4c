"""The soak experiment on a short loop: memory stays flat over a long run and a crowded frame."""

from __future__ import annotations

import pytest

from experiments import soak


def test_rss_is_read() -> None:
    assert 1.0 < soak.rss_mib() < 1e6


@pytest.mark.slow
def test_looped_video_and_crowd_keep_memory_flat() -> None:
    from pftrack.synthetic import make_scene

    scene = make_scene(n_frames=120, rng=0)
    runs = [
        soak.soak("synth", soak.looped_video(lambda: scene.frames), 1500, 100, 500),
        soak.soak("crowd", soak.crowd(100), 300, 25, 100),
    ]
    for r in runs:
        assert r.flat, r.row()
    assert len(runs[0].rss) == 16
