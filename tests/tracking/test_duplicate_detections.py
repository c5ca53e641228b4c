"""Duplicate detections (the same box twice in a frame) give one track, not two.

A detector without non-maximum suppression, or two detectors' outputs concatenated, gives
each object twice. Until 6 December every such pair started two tracks in the run's first
frames (``LifecycleConfig.birth_overlap`` then refused only a birth on a confirmed track), and
both lived on, each following one of the pair: 11-14 identities for 5 walkers.
"""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

import pftrack
from pftrack.cli import main
from pftrack.eval import iou_xywh
from pftrack.io.mot import group_by_frame, read_mot, write_mot
from pftrack.synthetic import make_scene
from pftrack.tracking import TrackerConfig
from pftrack.tracking.api import xywh_to_xyxy_dets
from pftrack.tracking.tracker import _classes, first_copies
from tests.conftest import dataset


@pytest.fixture(scope="module", params=[1, 2])
def scene(request):
    """Seed 2: a walker entering at the right border, whose track's box grows behind its
    detections, left its duplicate under IoU 0.3 with the track (a sixth identity, unless the
    detection it duplicates, matched to the track, counts too)."""
    return make_scene(n_frames=60, rng=request.param)


def truth_dets(scene, twice=None, rng=0):
    """Per-frame (N, 6) ``x1, y1, x2, y2, conf, cls`` from the truth; `twice` adds each box again.

    ``"exact"``: the same row; ``"jitter"``: each corner moved by up to 2 px (inside the
    frame; a sliver at a border is left as it is); ``"scores"``: the same box scored 0.6
    instead of 0.9, placed first. Rows shuffled.
    """
    g = np.random.default_rng(rng)
    by_frame = group_by_frame(scene.truth)
    out = []
    for f in range(1, len(scene.frames) + 1):
        r = by_frame.get(f, np.zeros((0, 10)))
        d = xywh_to_xyxy_dets(np.column_stack([r[:, 2:6], np.full(len(r), 0.9)]))
        if twice is not None:
            copy = d.copy()
            if twice == "jitter":
                wide = (d[:, 2:4] - d[:, :2] > 6.0).all(axis=1)[:, None]  # not a sliver at a border
                copy[:, :4] += g.uniform(-2.0, 2.0, (len(d), 4)) * wide
                copy[:, [0, 2]] = copy[:, [0, 2]].clip(0, scene.width)
                copy[:, [1, 3]] = copy[:, [1, 3]].clip(0, scene.height)
            if twice == "scores":
                copy[:, 4] = 0.6
            d = np.vstack([copy, d])  # the lower-scored copy first: order does not decide
        d = d[g.permutation(len(d))] if twice != "scores" else d
        out.append(np.column_stack([d, np.zeros(len(d))]))
    return out


def run(scene, dets, config=None, sampler="sis"):
    tracker = pftrack.Tracker(seed=0, prime=0, sampler=sampler)
    if config is not None:
        tracker = pftrack.Tracker.from_config(config, 0, prime_frames=0)
    online = [tracker.update(d, f) for d, f in zip(dets, scene.frames, strict=True)]
    return online, tracker.finalize()


def lifecycle(**changes):
    """The default TrackerConfig with `changes` to its LifecycleConfig."""
    config = TrackerConfig()
    return dataclasses.replace(config, lifecycle=dataclasses.replace(config.lifecycle, **changes))


def ids(online):
    return {int(r[4]) for out in online for r in out}


@pytest.fixture(scope="module")
def single(scene):
    return run(scene, truth_dets(scene))


@pytest.mark.parametrize("twice", ["exact", "jitter", "scores"])
def test_each_box_twice_gives_the_identities_of_each_box_once(scene, single, twice):
    online, rows = run(scene, truth_dets(scene, twice))
    assert len(ids(single[0])) == len(np.unique(scene.truth[:, 1]))  # the test's premise
    assert ids(online) == ids(single[0])  # was 11 for 5 walkers
    if twice != "jitter":  # jittered boxes are other boxes: the offline pass may cut or
        # join otherwise (seed 1: 4 identities, seed 2: 6; see the xfail below)
        assert len(np.unique(rows[:, 1])) == len(np.unique(single[1][:, 1]))
    if twice == "exact":  # the second copy changes nothing but the detection indices
        np.testing.assert_array_equal(rows, single[1])
        for a, b in zip(online, single[0], strict=True):
            np.testing.assert_array_equal(a[:, :7], b[:, :7])


@pytest.mark.dataset
@pytest.mark.parametrize("sampler", ["sis", "mh", "rjmcmc"])
def test_a_row_given_twice_is_one_detection_on_pets(sampler):
    """PETS09-S2L1's public detections, each row twice, 60 frames: the rows of each once.

    Was (the copies went to the association): from frame 23 a second track beside a
    person, which alone coasts and ends, took the spare copy every frame and lived on (the
    whole sequence: 30 tracks for 22, MOTA 80.7 -> 32.4). The synthetic scenes above have no
    such second track, so they did not show it. finalize()'s person-size fit counted each
    copy too (rjmcmc, the whole sequence: 4916 rows for 4899)."""
    folder = dataset("pets09-s2l1")
    by_frame = group_by_frame(read_mot(folder / "det.txt"))
    reader = cv2.VideoCapture(str(folder / "video.avi"))
    frames = [reader.read()[1] for _ in range(60)]
    once, twice = (pftrack.Tracker(seed=0, sampler=sampler) for _ in range(2))
    for f, frame in enumerate(frames, start=1):
        r = by_frame.get(f, np.zeros((0, 10)))
        d = xywh_to_xyxy_dets(np.column_stack([r[:, 2:6] * 0.625, r[:, 6]]))
        d = np.column_stack([d, np.zeros(len(d))])  # class 0
        a = once.update(d, frame)
        b = twice.update(np.vstack([d, d]), frame)
        np.testing.assert_array_equal(b[:, :7], a[:, :7])  # det_ind: either copy's row
    np.testing.assert_array_equal(twice.finalize(), once.finalize())


@pytest.mark.xfail(
    strict=True, reason="a duplicate is a free box for a neighbour's track to slide onto"
)
def test_jittered_duplicates_are_no_box_for_a_neighbour():
    """Known limit. Make_scene seed 2, each box twice with 2 px jitter: on frame 60, where
    walkers 1-4 crowd together, walker 3's track is matched to walker 1's spare copy, not to
    its own box (the assignment found it cheaper), and the offline pass ends that row as a
    one-row identity on walker 1 (IoU 0.96 with walker 1's track). The birth rules cannot
    help: it is an association, not a birth. A suppression of duplicates before association
    would, at an IoU above which two people's boxes never lie (no such constant is chosen):
    at birth_overlap's 0.3 it passes this test but costs experiments.public_detections'
    synthetic groups up to 3.0 MOTA and 6.8 IDF1 (measured 6 December, docs/tracking.md)."""
    scene = make_scene(n_frames=60, rng=2)
    _, rows = run(scene, truth_dets(scene, "jitter"))
    for frame_rows in group_by_frame(rows).values():
        iou = iou_xywh(frame_rows[:, 2:6], frame_rows[:, 2:6])
        assert (iou[np.triu_indices(len(iou), 1)] < 0.7).all()


@pytest.fixture(scope="module")
def single_joint(scene):
    return run(scene, truth_dets(scene), sampler="rjmcmc")


@pytest.mark.parametrize("twice", ["exact", "scores"])
def test_the_joint_sampler_births_one_object_per_duplicated_box(scene, single_joint, twice):
    """sampler="rjmcmc": a duplicate opens no newborn slot, by the per-object samplers' rule
    (``first_of_twins``); it still supports the identity it overlaps, as its twin does, so the
    rows are those of each box once. Was: both boxes of a pair were born (seed 1: 20 online
    identities for 10, seed 2: 15 for 7)."""
    online, rows = run(scene, truth_dets(scene, twice), sampler="rjmcmc")
    assert ids(online) == ids(single_joint[0])
    np.testing.assert_array_equal(rows[:, :7], single_joint[1][:, :7])


def test_the_joint_sampler_births_one_object_per_jittered_pair(scene, single_joint):
    """Jittered copies are other boxes (the chain's detection term and draws differ), so the
    identities are not those of each box once, but they are not doubled: 10 and 8 online
    identities for 10 and 7 (was 17 and 15)."""
    online, _ = run(scene, truth_dets(scene, "jitter"), sampler="rjmcmc")
    assert len(ids(online)) <= len(ids(single_joint[0])) + 1


def test_the_joint_sampler_births_both_with_the_rule_off(scene, single_joint):
    """birth_overlap=None reaches the joint sampler too: each box of a (jittered) pair may be
    born."""
    config = dataclasses.replace(lifecycle(birth_overlap=None), sampler="rjmcmc")
    online, _ = run(scene, truth_dets(scene, "jitter"), config)
    assert len(ids(online)) > len(ids(single_joint[0])) + 2


@pytest.mark.parametrize("twice", ["exact", "jitter", "scores"])
def test_mh_births_one_track_per_duplicated_box(scene, twice):
    """sampler="mh" swaps only the filter: its tracks are born by the same rule as sis's."""
    online, _ = run(scene, truth_dets(scene, twice), sampler="mh")
    assert len(ids(online)) == len(np.unique(scene.truth[:, 1]))


def test_finalize_fits_the_person_size_to_each_box_once(scene):
    """finalize()'s person-size fit (``LifecycleConfig.size_ratio``) takes the frame's boxes
    once, whatever copies were given (was: each copy; on PETS09-S2L1 given twice with
    sampler="rjmcmc" that moved 17 of the final rows)."""
    trackers = []
    for twice in (None, "scores"):
        tracker = pftrack.Tracker(seed=0, prime=0)
        for d, f in zip(truth_dets(scene, twice), scene.frames, strict=True):
            tracker.update(d, f)
        trackers.append(tracker)
    once, copies = (np.vstack(t._sizes) for t in trackers)
    np.testing.assert_array_equal(copies[np.lexsort(copies.T)], once[np.lexsort(once.T)])


def test_the_size_samples_look_for_copies_only_on_frames_that_hold_one(scene, monkeypatch):
    """Tracker.update's size samples look for copies (``first_copies``) only on the frames
    whose rows the tracker inside found a copy among (``MultiObjectTracker.copies_given``):
    a frame without one has none among its scored rows either (was: on every frame, a
    second pass of about 7 us beside the tracker's)."""
    calls = []

    def counted(boxes, labels):
        calls.append(len(boxes))
        return first_copies(boxes, labels)

    monkeypatch.setattr(pftrack.tracking.api, "first_copies", counted)
    plain, twice = truth_dets(scene), truth_dets(scene, "exact")
    given = [k for k in range(12) if len(plain[k])][1::4][:2]  # two frames given twice
    tracker = pftrack.Tracker(seed=0, prime=0)
    found = []
    for k in range(12):
        tracker.update(twice[k] if k in given else plain[k], scene.frames[k])
        found.append(tracker._tracker.copies_given)
    assert len(given) == 2
    assert found == [k in given for k in range(12)]
    assert calls == [2 * len(plain[k]) for k in given]  # the scored rows, copies included
    sizes = np.vstack(tracker._sizes)
    for k in given:  # each box once
        at = sizes[sizes[:, 3] == k]
        assert len(at) == len(plain[k])


@pytest.mark.parametrize("labels", [[], [0], [0, 0, 0], [3, -1, 3, 0, 2**31 - 1, -(2**31)]])
def test_classes_are_np_unique_on_plain_ints(labels):
    a = np.array(labels, np.int64)
    out = _classes(a)
    assert out == np.unique(a).tolist()
    assert all(type(c) is int for c in out)


def test_first_copies_keeps_the_first_of_each_box_and_class():
    boxes = np.array([[1.0, 2, 3, 4], [5, 6, 7, 8], [1, 2, 3, 4], [1, 2, 3, 4], [5, 6, 7, 8]])
    assert first_copies(boxes, np.array([0, 0, 0, 1, 1])).tolist() == [0, 1, 3, 4]
    assert first_copies(boxes, np.array([0.0, 1.0, 1.0, 2.0, 3.0])) is None  # other classes
    assert first_copies(boxes[:2], np.zeros(2, np.int64)) is None


def test_a_duplicate_that_starts_no_track_is_in_no_row(scene):
    """det_ind, as BoxMOT's: each row's index is the detection its track followed; a
    suppressed duplicate is in no row. At birth that is the higher-scored box of the pair.
    Both boxes pass the birth threshold here (the learned one would refuse the 0.6 box)."""
    dets = truth_dets(scene, "scores")
    online, _ = run(scene, dets, lifecycle(birth_quantile=None, birth_score=0.5))
    first = online[0]
    assert len(first) == len(dets[0]) // 2 == 1
    det_ind = int(first[0, 7])
    assert dets[0][det_ind, 4] == 0.9  # the 0.9 box, given second, not the 0.6 one
    for out, d in zip(online, dets, strict=True):
        assert len(set(out[:, 7].tolist())) == len(out)  # one detection, one track
        assert set(out[:, 7].astype(int).tolist()) <= set(range(len(d)))


def test_duplicates_are_two_tracks_with_the_rule_off(scene, single):
    """birth_overlap=None turns the rule off, for duplicates too: each box starts two tracks.

    Jittered copies: a row given exactly twice is one detection whatever the rule
    (``first_copies``; since 6 December)."""
    online, _ = run(scene, truth_dets(scene, "jitter"), lifecycle(birth_overlap=None))
    assert len(ids(online)) >= 2 * len(ids(single[0]))


@pytest.mark.parametrize("start", [1, 2, 8])
def test_a_second_box_beside_a_tentative_track_starts_no_track(start):
    """A box overlapping the first by IoU 0.43 from frame `start`: in the same frame as the
    first one's birth (1), beside its tentative track (2), or its confirmed one (8)."""
    frame = np.zeros((80, 100, 3), np.uint8)
    frame[20:60, 30:58] = (40, 60, 220)
    box, second = [30.0, 20.0, 50.0, 60.0, 0.95, 0.0], [38.0, 20.0, 58.0, 60.0, 0.9, 0.0]
    tracker = pftrack.Tracker(seed=0, prime=0)
    found = set()
    for k in range(1, 15):
        found |= {
            int(r[4]) for r in tracker.update(np.array([box, second][: 1 + (k >= start)]), frame)
        }
    assert len(found) == 1


@pytest.mark.parametrize("sampler", ["sis", "mh", "rjmcmc"])
def test_the_cli_keeps_one_track_per_duplicated_box(scene, tmp_path, sampler):
    video = scene.write_video(tmp_path / "scene.avi")
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 0.9
    write_mot(tmp_path / "once.txt", det)
    write_mot(tmp_path / "twice.txt", np.vstack([det, det]))
    for name in ("once", "twice"):
        det_path, out = tmp_path / f"{name}.txt", tmp_path / f"{name}_tracks.txt"
        argv = ["-q", "track", str(video), "--detections", str(det_path), "--out", str(out)]
        assert main([*argv, "--sampler", sampler]) == 0
    once, twice = (read_mot(tmp_path / f"{n}_tracks.txt") for n in ("once", "twice"))
    if sampler != "rjmcmc":  # the joint chain churns identities of its own (docs/samplers.md)
        assert len(np.unique(once[:, 1])) >= len(np.unique(scene.truth[:, 1])) - 1
    np.testing.assert_array_equal(twice, once)  # was: 11 and 12 tracks for 5 walkers
