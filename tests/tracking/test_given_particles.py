"""Particles per object with given detections (TrackerConfig.given_particles).

Tracks born from a given detection carry ``given_particles`` (200) particles, the built-in
detector's tracks ``filter.n_particles`` (100); an explicit count (``Tracker(particles=N)``,
``pftrack track --particles N``) holds for both.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import pftrack
from pftrack.cli import build_parser
from pftrack.cli._options import tracker_config
from pftrack.io.mot import group_by_frame
from pftrack.synthetic import make_scene
from pftrack.tracking import MultiObjectTracker, TrackerConfig


@pytest.fixture(scope="module")
def scene_and_dets():
    scene = make_scene(n_frames=12, n_walkers=3, rng=1, occluder=False)
    by_frame = group_by_frame(scene.truth)
    dets = []
    for n in range(1, len(scene.frames) + 1):
        r = by_frame.get(n, np.zeros((0, 10)))
        dets.append(np.column_stack([r[:, 2:6], np.full(len(r), 0.95)]))
    return scene, dets


def _particle_counts(tracker: MultiObjectTracker) -> set[int]:
    return {len(t.filter.particles) for t in tracker.tracks}


def test_tracks_of_given_detections_carry_given_particles(scene_and_dets):
    scene, dets = scene_and_dets
    tracker = MultiObjectTracker(rng=0)
    for frame, d in zip(scene.frames, dets, strict=True):
        tracker.update(frame, d)
    assert tracker.tracks and _particle_counts(tracker) == {200}
    assert TrackerConfig().given_particles == 200


def test_builtin_detector_tracks_keep_the_filter_count(scene_and_dets):
    scene, _ = scene_and_dets
    tracker = MultiObjectTracker(rng=0)
    for frame in scene.frames:
        tracker.update(frame)
    assert tracker.tracks and _particle_counts(tracker) == {100}


@pytest.mark.parametrize(("given", "filter_n", "expected"), [(None, 100, 100), (50, 100, 50)])
def test_given_particles_setting(scene_and_dets, given, filter_n, expected):
    scene, dets = scene_and_dets
    base = TrackerConfig(given_particles=given)
    config = replace(base, filter=replace(base.filter, n_particles=filter_n))
    tracker = MultiObjectTracker(config, rng=0)
    for frame, d in zip(scene.frames[:4], dets[:4], strict=True):
        tracker.update(frame, d)
    assert tracker.tracks and _particle_counts(tracker) == {expected}


def test_more_particles_change_the_run_and_stay_reproducible(scene_and_dets):
    scene, dets = scene_and_dets

    def states(config: TrackerConfig) -> list[np.ndarray]:
        tracker = MultiObjectTracker(config, rng=3)
        for frame, d in zip(scene.frames, dets, strict=True):
            tracker.update(frame, d)
        return [t.filter.particles.copy() for t in tracker.tracks]

    a, b = states(TrackerConfig()), states(TrackerConfig())
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    c = states(TrackerConfig(given_particles=None))
    assert [len(x) for x in a] != [len(x) for x in c]


@pytest.mark.parametrize("value", [0, -1, True, 2.5, "200", 10**7])
def test_bad_given_particles_are_refused(value):
    with pytest.raises(ValueError, match="given_particles"):
        TrackerConfig(given_particles=value)


def test_an_explicit_count_holds_for_both_modes():
    tracker = pftrack.Tracker(particles=150)
    assert tracker.config.filter.n_particles == 150 and tracker.config.given_particles is None
    default = pftrack.Tracker()
    assert default.config.filter.n_particles == 100 and default.config.given_particles == 200
    with pytest.raises(ValueError, match="particles is 0"):
        pftrack.Tracker(particles=0)
    for bad in (True, 2.5):  # not an integer: a TypeError, as for every option
        with pytest.raises(TypeError, match="particles must be an integer"):
            pftrack.Tracker(particles=bad)


def test_cli_particles():
    parser = build_parser()
    args = parser.parse_args(["track", "v.avi", "--out", "t.txt"])
    cfg = tracker_config(args)
    assert (cfg.filter.n_particles, cfg.given_particles) == (100, 200)
    args = parser.parse_args(["track", "v.avi", "--out", "t.txt", "--particles", "40"])
    cfg = tracker_config(args)
    assert (cfg.filter.n_particles, cfg.given_particles) == (40, None)
    with pytest.raises(SystemExit) as e:
        parser.parse_args(["track", "v.avi", "--out", "t.txt", "--particles", "-1"])
    assert e.value.code == 2
