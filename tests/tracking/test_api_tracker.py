"""pftrack.Tracker: the drop-in contract (update, finalize, reset), its inputs and the CLI."""

from __future__ import annotations

import copy
import dataclasses
import itertools
import re
import sys
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

import pftrack
from pftrack.cli import main
from pftrack.eval import evaluate_mot, iou_xywh
from pftrack.io.mot import group_by_frame, read_mot, write_mot
from pftrack.io.video import FrameSource
from pftrack.recovery.linking import LinkConfig
from pftrack.synthetic import make_busy_scene, make_scene
from pftrack.tracking import TrackerConfig, load_detections, track_frames
from pftrack.tracking.api import check_boxes_xyxy, xywh_to_xyxy_dets
from pftrack.tracking.offline import complete_boxes, drop_nested
from tests.conftest import dataset

# Many contract tests feed placeholder frames (np.zeros): the warning they give is tested below.
pytestmark = pytest.mark.filterwarnings("ignore:frame 1 is blank")


@pytest.fixture(scope="module")
def scene():
    return make_scene(n_frames=40, rng=1)


def scene_dets(scene, scores=None, rng=0):
    """Per-frame (N, 5) x1, y1, x2, y2, conf from the scene's truth (shuffled rows)."""
    g = np.random.default_rng(rng)
    by_frame = group_by_frame(scene.truth)
    out = []
    for f in range(1, len(scene.frames) + 1):
        r = by_frame.get(f, np.zeros((0, 10)))
        r = r[g.permutation(len(r))]
        conf = np.ones(len(r)) if scores is None else g.uniform(*scores, len(r))
        out.append(xywh_to_xyxy_dets(np.column_stack([r[:, 2:6], conf])))
    return out


def run_loop(tracker, frames, dets):
    outs = [tracker.update(d, f) for d, f in zip(dets, frames, strict=True)]
    return outs, tracker.finalize()


# -- the contract on real sequences ----------------------------------------------------------
SEQUENCES = {
    "pets09-s2l1": ("video.avi", 0.625),
    "tud-campus": ("video.mp4", 1.0),
}
#: Frames of a sequence the loop is compared on, where not all: PETS09's 795 frames took
#: 147 s of CI's 2 busy cores (the CLI and the loop each track the whole video); its first
#: 200 give 9 tracks, 1116 rows, 54 of them filled by the offline pass, at det.txt's 0.625.
CLIP = {"pets09-s2l1": 200}


def _clip(folder: Path, video: str, n: int, into: Path) -> tuple[Path, Path]:
    """The first `n` frames of `folder`'s `video` (an MJPG AVI) and its det.txt's rows of them.

    Both the command and the loop read the clip: what they must agree on is its frames, not
    the original's pixels.
    """
    clip, det = into / "clip.avi", into / "det.txt"
    source = FrameSource(folder / video)
    first = next(iter(source))
    writer = cv2.VideoWriter(str(clip), cv2.VideoWriter_fourcc(*"MJPG"), 7.0, first.shape[1::-1])
    for frame in itertools.islice(FrameSource(folder / video), n):
        writer.write(frame)
    writer.release()
    rows = read_mot(folder / "det.txt")
    write_mot(det, rows[rows[:, 0] <= n], exact=True)
    return clip, det


@pytest.mark.dataset
@pytest.mark.parametrize(
    ("name", "dtype"),
    [*((name, np.float64) for name in sorted(SEQUENCES)), ("tud-campus", np.float32)],
)
def test_documented_loop_is_the_cli_byte_for_byte(name, dtype, tmp_path):
    """float32: a detector's usual dtype; its scores were written rounded to 2 decimals."""
    folder = dataset(name)
    video, scale = SEQUENCES[name]
    source, det_path = folder / video, folder / "det.txt"
    if name in CLIP:
        source, det_path = _clip(folder, video, CLIP[name], tmp_path)
    cli_out = tmp_path / "cli.txt"
    argv = ["track", str(source), "--detections", str(det_path)]
    assert main([*argv, "--det-scale", str(scale), "--out", str(cli_out)]) == 0

    # the README's loop: a detector's (N, 5) x1, y1, x2, y2, conf per frame
    det = read_mot(det_path)
    by_frame = group_by_frame(det)
    tracker = pftrack.Tracker(frame_rate=25.0)
    tracker.prime(itertools.islice(iter(FrameSource(source)), 30))
    for n, frame in enumerate(FrameSource(source), start=1):
        r = by_frame.get(n, np.zeros((0, 10)))
        dets = np.column_stack([r[:, 2:4] * scale, (r[:, 2:4] + r[:, 4:6]) * scale, r[:, 6]])
        # x2 as the CLI computes it, from the scaled left and width: same floats, same bytes
        dets[:, 2:4] = r[:, 2:4] * scale + r[:, 4:6] * scale
        dets = dets.astype(dtype)
        tracks = tracker.update(dets, frame)
        assert tracks.shape[1] == 8 and tracks.dtype == np.float64
        ids = tracks[:, 4]
        assert len(set(ids)) == len(ids) and np.all(ids >= 1) and np.all(ids == np.round(ids))
        di = tracks[:, 7].astype(int)
        assert np.all((di >= 0) & (di < len(dets)))  # every reported track has its detection
        np.testing.assert_array_equal(tracks[:, 5], dets[di, 4])
        assert np.all(tracks[:, 6] == 0)
    rows = tracker.finalize()
    api_out = tmp_path / "api.txt"
    write_mot(api_out, rows)
    # the same bytes, so the same scores: evaluating both (was) could not tell them apart
    assert api_out.read_bytes() == cli_out.read_bytes()
    assert len(set(rows[:, 1])) >= 4  # people tracked, not a run of no track


@pytest.mark.dataset
@pytest.mark.xfail(
    strict=True,
    reason="unprimed, the background learns the first 30 frames' running mean, people walking "
    "through them included: TUD-Campus 76.9 / 77.7 against the command's 79.4 / 85.4 (MOTA / "
    "IDF1); priming online from the first 30 frames closed it there and lost on PETS09; the "
    "median of the frames so far, and learning only the pixels no given box covers, closed it "
    "and lost on the synthetic groups and overhead: none adopted (docs/tracking.md, 'A loop "
    "without prime')",
)
def test_unprimed_loop_scores_the_commands():
    # README: "prime is optional". A user's loop that does not call it (trial59)
    folder = dataset("tud-campus")
    gt = read_mot(folder / "gt.txt")
    by_frame = group_by_frame(read_mot(folder / "det.txt"))
    scores = []
    for primed in (True, False):
        tracker = pftrack.Tracker(frame_rate=25.0)
        if primed:  # as pftrack track --detections
            tracker.prime(itertools.islice(iter(FrameSource(folder / "video.mp4")), 30))
        for n, frame in enumerate(FrameSource(folder / "video.mp4"), start=1):
            r = by_frame.get(n, np.zeros((0, 10)))
            tracker.update(np.column_stack([r[:, 2:4], r[:, 2:4] + r[:, 4:6], r[:, 6]]), frame)
        scores.append(evaluate_mot(gt, tracker.finalize()))
    command, loop = scores
    assert command.mota > 0.79 and command.idf1 > 0.85  # the command's figures (README)
    assert loop.mota >= command.mota - 0.003 and loop.idf1 >= command.idf1 - 0.003


README = Path(__file__).resolve().parents[2] / "README.md"


def _readme_loops() -> tuple[str, str]:
    """The README's two drop-in loops: with a detector's boxes, and with the built-in one."""
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    first = next(b for b in blocks if "tracker.prime(itertools.islice(" in b)
    built_in = next(b for b in blocks if "bootstrap_frames(" in b and "update(None" in b)
    return first, built_in


@pytest.mark.parametrize("which", ["built-in", "first"])
def test_readme_loop_with_the_built_in_detector_is_the_cli(which, tmp_path):
    """The README said its loop (the first 30 frames primed) is what ``pftrack track`` does;
    with the built-in detector the command primes with 30 frames spread over the file (4519
    boxes against 4507 on PETS09). Its second loop is the command; its first, with
    ``dets=None``, is ``--bootstrap first``. Run as the README writes them."""
    scene = make_scene(n_frames=80, width=192, height=144, n_walkers=3, rng=1)
    video = tmp_path / "video.avi"
    scene.write_video(video)
    first, built_in = _readme_loops()
    code = built_in if which == "built-in" else first
    code = code.replace("my_detector(frame)", "None").replace("tracker.reset()", "")
    namespace: dict[str, object] = {}
    exec(code.replace('"video.avi"', repr(str(video))), namespace)  # noqa: S102 - the README's
    write_mot(tmp_path / "api.txt", namespace["rows"])
    argv = ["-q", "track", str(video), "--out", str(tmp_path / "cli.txt")]
    assert main(argv if which == "built-in" else [*argv, "--bootstrap", "first"]) == 0
    cli = (tmp_path / "cli.txt").read_bytes()
    assert len(cli) > 0 and (tmp_path / "api.txt").read_bytes() == cli


# -- update's output ------------------------------------------------------------------------
def test_update_returns_confirmed_matched_tracks_with_det_ind(scene):
    dets = scene_dets(scene)
    tracker = pftrack.Tracker(seed=0)
    outs, rows = run_loop(tracker, scene.frames, dets)
    assert sum(len(o) for o in outs) > 0.8 * len(scene.truth)
    for o, d in zip(outs, dets, strict=True):
        assert o.shape[1] == 8
        di = o[:, 7].astype(int)
        assert np.all(di >= 0)
        # the track's box sits on the detection it names (a shuffled order must not matter)
        centre_t = (o[:, :2] + o[:, 2:4]) / 2
        centre_d = (d[di, :2] + d[di, 2:4]) / 2
        assert np.all(np.abs(centre_t - centre_d) < 0.5 * (d[di, 3] - d[di, 1])[:, None])
    assert rows.shape[1] == 10 and len(rows) >= sum(len(o) for o in outs) * 0.9
    m = evaluate_mot(scene.truth, rows)
    assert m.mota > 0.7 and m.idf1 > 0.8  # measured 0.79 / 0.89


def test_update_drops_coasting_tracks_that_the_old_api_reports(scene):
    """Frames without detections: update reports no box; MultiObjectTracker still coasts."""
    dets = scene_dets(scene)[:15]
    tracker = pftrack.Tracker(seed=0, prime=0)
    for d, f in zip(dets, scene.frames, strict=False):
        tracker.update(d, f)
    frame = scene.frames[15]
    assert len(tracker.update(np.zeros((0, 5)), frame)) == 0
    coasting = [t for t in tracker.tracker.tracks if t.time_since_update == 1]
    assert coasting  # still alive inside, held back for finalize's offline pass


def test_reset_gives_a_fresh_tracker(scene):
    dets = scene_dets(scene)
    tracker = pftrack.Tracker(seed=3)
    outs_a, rows_a = run_loop(tracker, scene.frames, dets)
    tracker.reset()
    outs_b, rows_b = run_loop(tracker, scene.frames, dets)
    outs_c, rows_c = run_loop(pftrack.Tracker(seed=3), scene.frames, dets)
    for a, b, c in zip(outs_a, outs_b, outs_c, strict=True):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)
    np.testing.assert_array_equal(rows_a, rows_b)
    np.testing.assert_array_equal(rows_a, rows_c)
    # and the seed matters (the particle filters draw from it)
    _, rows_d = run_loop(pftrack.Tracker(seed=4, smooth=False), scene.frames, dets)
    _, rows_e = run_loop(pftrack.Tracker(seed=3, smooth=False), scene.frames, dets)
    assert not np.array_equal(rows_d, rows_e)


def test_classes_never_share_an_identity():
    """One object seen as class 0, then as class 1 in the same place: two identities."""
    frame = np.zeros((80, 100, 3), np.uint8)
    frame[20:60, 30:50] = (40, 60, 220)
    box = [30.0, 20.0, 50.0, 60.0, 0.95]
    tracker = pftrack.Tracker(seed=0, prime=0)
    ids: dict[int, set[int]] = {}
    for k in range(12):
        cls = 0 if k < 6 else 1
        out = tracker.update(np.array([[*box, cls]]), frame)
        for row in out:
            ids.setdefault(int(row[4]), set()).add(int(row[6]))
    assert all(len(c) == 1 for c in ids.values())
    assert {c for cs in ids.values() for c in cs} == {0, 1}  # both classes were tracked
    # the same run with one class keeps one identity
    tracker = pftrack.Tracker(seed=0, prime=0)
    one = set()
    for _ in range(12):
        one |= {int(r[4]) for r in tracker.update(np.array([box]), frame)}
    assert len(one) == 1


@pytest.mark.parametrize(("overlap", "cls", "n_ids"), [(0.3, 0, 1), (None, 0, 2), (0.3, 1, 2)])
def test_a_second_box_on_a_followed_person_starts_no_track(overlap, cls, n_ids):
    """LifecycleConfig.birth_overlap: from frame 9 a second detection overlaps the confirmed
    track by IoU 0.43. It starts no track, unless it is of another class or the rule is off."""
    frame = np.zeros((80, 100, 3), np.uint8)
    frame[20:60, 30:58] = (40, 60, 220)
    box, second = [30.0, 20.0, 50.0, 60.0, 0.95, 0.0], [38.0, 20.0, 58.0, 60.0, 0.95, cls]
    config = TrackerConfig()
    config = dataclasses.replace(
        config, lifecycle=dataclasses.replace(config.lifecycle, birth_overlap=overlap)
    )
    tracker = pftrack.Tracker.from_config(config, 0, prime_frames=0)
    ids = set()
    for k in range(20):
        dets = np.array([box, second] if k >= 8 else [box])
        ids |= {int(r[4]) for r in tracker.update(dets, frame)}
    assert len(ids) == n_ids


def test_birth_overlap_is_checked():
    for bad in (0.0, 1.5, -0.1):
        with pytest.raises(ValueError, match="birth_overlap is .*, expected a value in"):
            pftrack.tracking.LifecycleConfig(birth_overlap=bad)
    with pytest.raises(TypeError, match="birth_overlap"):
        pftrack.tracking.LifecycleConfig(birth_overlap="0.3")  # type: ignore[arg-type]


@pytest.mark.parametrize("cls", [0.7, -0.5, 1e20, 2.0**31 + 1, 2.0**31, -(2.0**31) - 1])
def test_class_ids_must_be_integers(cls):
    frame = np.zeros((80, 100, 3), np.uint8)
    dets = np.array([[30.0, 20.0, 50.0, 60.0, 0.9, 0.0], [60.0, 20.0, 80.0, 60.0, 0.9, cls]])
    with pytest.raises(
        ValueError,
        match=r"dets row 1 has class id .*, expected an integer in \[-2147483648, 2147483647\]",
    ):
        pftrack.Tracker().update(dets, frame)
    for edge in (2.0**31 - 1, -(2.0**31)):  # int32's own bounds are class ids
        dets[1, 5] = edge
        assert pftrack.Tracker().update(dets, frame).shape[1] == 8
    dets[1, 5] = 3.0  # an integer held as a float is a class id
    assert pftrack.Tracker().update(dets, frame).shape[1] == 8


@pytest.mark.parametrize("second_class", [0, 1])
def test_finalize_never_links_two_classes(scene, second_class):
    """A walker seen as class 0, undetected for 12 frames, then seen as `second_class`.

    With one class the offline pass links the two tracks into one identity; with two it must
    not (it did: finalize() gave one id to both classes, the user trial's defect).
    """
    who = int(scene.truth[0, 1])
    rows = scene.truth[scene.truth[:, 1] == who]
    tracker = pftrack.Tracker(seed=0, prime=0)
    online: dict[int, set[int]] = {}
    for f in range(1, 41):
        r = rows[rows[:, 0] == f]
        cls = 0 if f <= 14 else second_class
        dets = np.zeros((0, 6))
        if len(r) and not 15 <= f <= 26:  # frames 15-26: no detection
            x, y, w, h = r[0, 2:6]
            dets = np.array([[x, y, x + w, y + h, 0.95, cls]])
        for t in tracker.update(dets, scene.frames[f - 1]):
            online.setdefault(int(t[4]), set()).add(int(t[6]))
    assert len(online) == 2  # longer than max_coast (10 frames): a new id after the gap
    final = tracker.finalize()
    before = set(final[final[:, 0] <= 14, 1].astype(int))
    after = set(final[final[:, 0] >= 27, 1].astype(int))
    assert len(before) == len(after) == 1
    if second_class == 0:
        assert before == after  # linked: one identity
    else:
        assert before != after  # two classes: two identities, as update() gave
    # each final id's class (finalize() renumbers ids; the rows have no class column)
    (b,), (a,) = before, after
    assert tracker.classes == {b: 0, a: second_class}
    tracker.reset()
    assert tracker.classes == {}


def test_classes_of_final_ids_follow_the_detections(scene):
    """Two classes by the side of the frame a detection is on: each id finalize() returns has
    the class of the detections it was made of (was: the rows said no class, and the ids
    were renumbered)."""
    tracker = pftrack.Tracker(seed=0, prime=0)
    w = scene.frames[0].shape[1]
    for f, dets in enumerate(scene_dets(scene), start=1):
        if len(dets):
            side = ((dets[:, 0] + dets[:, 2]) / 2 > w / 2).astype(float)
            dets = np.column_stack([dets[:, :5], side])
        tracker.update(dets, scene.frames[f - 1])
    rows = tracker.finalize()
    assert set(tracker.classes) == set(rows[:, 1].astype(int).tolist())
    assert set(tracker.classes.values()) == {0, 1}
    for i, c in tracker.classes.items():
        r = rows[(rows[:, 1] == i) & (rows[:, 7] != 1)]  # not the rows filled in holes
        centre = r[:, 2] + r[:, 4] / 2
        assert np.mean((centre > w / 2) == bool(c)) > 0.8


def test_merged_blob_rows_name_the_blob():
    from pftrack.tracking import LifecycleConfig, RefineConfig
    from pftrack.tracking.tracker import MultiObjectTracker

    frame = np.zeros((80, 120, 3), np.uint8)
    frame[20:60, 20:36] = (40, 60, 220)
    frame[20:60, 40:56] = (220, 60, 40)
    config = TrackerConfig(lifecycle=LifecycleConfig(min_hits=1), refine=RefineConfig(False))
    mot = MultiObjectTracker(config, rng=0)
    two = np.array([[20, 20, 16, 40, 1.0], [40, 20, 16, 40, 1.0]])
    assert sorted(t.id for t in mot.update(frame, two)) == [1, 2]
    blob = np.array([[100.0, 0.0, 3.0, 3.0, 1.0], [18, 18, 40, 44, 1.0]])  # both people inside
    tracks = [t for t in mot.update(frame, blob) if t.id in (1, 2)]
    matched = [t for t in tracks if t.time_since_update == 0]
    assert [t.detection_index for t in matched] == [1]  # the blob, no longer None
    assert matched[0].detection_box is None  # a blob does not re-seed the track


@pytest.mark.parametrize("person_class", [0, 2])
def test_a_blob_is_made_of_tracks_of_its_class(person_class):
    """A car (class 2) whose box grows 3x in one frame, now holding a person's centre.

    A detector's box of one class is no blob of another class's objects: the car's track
    follows its new box when the person is of another class (was: it kept its old box, as
    it does when the person is of the car's class, a merged blob).
    """
    frame = np.random.default_rng(0).integers(0, 255, (240, 320, 3), dtype=np.uint8)
    frame[100:180, 100:130] = (0, 0, 200)
    frame[120:170, 140:200] = (200, 0, 0)
    person = [100.0, 100.0, 130.0, 180.0, 0.95, person_class]
    tracker = pftrack.Tracker(refine=False)
    for k in range(20):
        car = (
            [140.0, 120.0, 200.0, 170.0, 0.95, 2]
            if k < 10
            else [90.0, 110.0, 230.0, 180.0, 0.95, 2]
        )
        out = tracker.update(np.array([person, car]), frame)
    (row,) = out[out[:, 7] == 1]
    followed = np.abs(row[:4] - car[:4]).max() < 5  # the car's new box, 90, 110, 230, 180
    assert followed == (person_class != 2)


# -- birth gates -----------------------------------------------------------------------------
def test_low_score_detector_still_gives_tracks(scene):
    dets = scene_dets(scene, scores=(0.2, 0.5))
    outs, rows = run_loop(pftrack.Tracker(seed=0), scene.frames, dets)
    assert len(rows) > 0 and sum(len(o) for o in outs) > 0
    assert evaluate_mot(scene.truth, rows).mota > 0.5
    # the fixed 0.9 threshold of before drops the whole detector, and says so
    with pytest.warns(RuntimeWarning, match="no track over 40 frames.*highest detection"):
        run_loop(pftrack.Tracker(seed=0, birth_quantile=None), scene.frames, dets)


def test_min_conf_ignores_detections(scene):
    dets = scene_dets(scene, scores=(0.2, 0.5))
    with pytest.warns(RuntimeWarning, match="no track"):
        outs, rows = run_loop(pftrack.Tracker(seed=0, min_conf=0.6), scene.frames, dets)
    assert len(rows) == 0


def test_cli_warns_when_no_track(scene, tmp_path, capsys):
    video = tmp_path / "scene.avi"
    scene.write_video(video)
    det = scene.truth.copy()
    det[:, 1], det[:, 6] = -1, 0.3
    write_mot(tmp_path / "det.txt", det)
    out = tmp_path / "t.txt"
    argv = ["track", str(video), "--detections", str(tmp_path / "det.txt"), "--out", str(out)]
    assert main([*argv, "--min-conf", "0.5"]) == 0
    assert "pftrack track: warning: no track" in capsys.readouterr().err
    assert main(argv) == 0  # the default birth threshold follows the detector's scores
    assert len(read_mot(out)) > 0 and "warning" not in capsys.readouterr().err


# -- inputs ----------------------------------------------------------------------------------
def as_xywh(d: np.ndarray) -> np.ndarray:
    xywh = d.copy()
    xywh[:, 2:4] = d[:, 2:4] - d[:, :2]
    return xywh


def test_xywh_given_as_xyxy_is_refused(scene):
    # the scene's first frame holds one box: a lone inverted box is dropped (a stray box),
    # the second frame's make all of the run's boxes inverted, and the run is refused
    d = scene_dets(scene)
    assert len(d[0]) == 1
    tracker = pftrack.Tracker()
    with pytest.warns(UserWarning, match=r"^1 detection box with x2 < x1 or y2 < y1 ignored"):
        tracker.update(as_xywh(d[0]), scene.frames[0])
    n = 1 + len(d[1])
    message = (
        rf"^dets row 0 .* has x2 < x1 or y2 < y1, as have {n} of the {n} boxes given so far: "
        r"the boxes look like x, y, w, h; give x1, y1, x2, y2 \(x2 = x \+ w, y2 = y \+ h\)$"
    )
    with pytest.raises(ValueError, match=message):
        tracker.update(as_xywh(d[1]), scene.frames[1])
    assert tracker.frame_count == 1  # the refused frame changed nothing
    k = next(k for k, v in enumerate(d) if len(v) >= 3)  # several in one frame: at once
    with pytest.raises(ValueError, match=r"^dets row 0 .* boxes given: the boxes look like x, y"):
        pftrack.Tracker().update(as_xywh(d[k]), scene.frames[k])


def test_a_box_without_area_among_good_ones_is_dropped_with_a_warning(scene):
    # a box trimmed to zero width at the frame's edge refused the whole frame, saying the
    # boxes looked like x, y, w, h (a user trial with TUD-Campus's det.txt)
    k = next(k for k, d in enumerate(scene_dets(scene)) if len(d) >= 3)
    d = scene_dets(scene)[k]
    h, w = scene.frames[k].shape[:2]
    dets = np.vstack([d, [[w, 10, w, 60, 0.95]], [[30, 40, 20, 90, 0.95]]])
    tracker = pftrack.Tracker(seed=0, prime=0)
    with pytest.warns(UserWarning) as caught:
        out = tracker.update(dets, scene.frames[k])
    assert [str(c.message).split(";")[0] for c in caught] == [
        "1 detection box without area (x2 == x1 or y2 == y1) ignored",
        "1 detection box with x2 < x1 or y2 < y1 ignored (x1, y1, x2, y2 expected)",
    ]
    assert not np.isin(out[:, 7], [len(d), len(d) + 1]).any()  # never matched
    ref = pftrack.Tracker(seed=0, prime=0).update(d, scene.frames[k])
    np.testing.assert_array_equal(out, ref)  # the rest as without them
    checked = check_boxes_xyxy(dets, (h, w))
    assert (checked.flat, checked.inverted, checked.extent) == (1, 1, len(d) + 1)
    assert list(checked.kept) == list(range(len(d)))


@pytest.mark.parametrize("n", [1, 3])
def test_a_frame_of_boxes_without_area_only_is_dropped_with_a_warning(scene, n):
    # a frame whose only detection had no area raised "the boxes look like x, y, w, h" (more
    # than half its rows were bad), while 1 of 2 or 3 was dropped: now any number is dropped
    d = scene_dets(scene)
    h, w = scene.frames[0].shape[:2]
    a = pftrack.Tracker()
    for k in range(3):
        a.update(d[k], scene.frames[k])
    b = copy.deepcopy(a)
    flat = np.array([[w, 10, w, 50, 0.4], [10, 20, 30, 20, 0.9], [5, 5, 5, 5, 0.9]])[:n]
    with pytest.warns(UserWarning, match=f"^{n} detection box(es)? without area"):
        out = a.update(flat, scene.frames[3])
    np.testing.assert_array_equal(out, b.update(np.zeros((0, 5)), scene.frames[3]))
    for k in range(4, 12):  # the run goes on as without them
        np.testing.assert_array_equal(
            a.update(d[k], scene.frames[k]), b.update(d[k], scene.frames[k])
        )
    np.testing.assert_array_equal(a.finalize(), b.finalize())


def test_a_stray_inverted_box_never_refuses_a_run(scene):
    d = scene_dets(scene)
    tracker = pftrack.Tracker()
    for k in range(6):
        tracker.update(d[k], scene.frames[k])
    stray = np.array([[40.0, 10, 20, 60, 0.9]])  # x2 < x1
    with pytest.warns(UserWarning, match="^1 detection box with x2 < x1"):
        tracker.update(stray, scene.frames[6])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # warned once a run
        tracker.update(stray, scene.frames[7])  # two of the run's boxes, not most of them
        tracker.update(np.vstack([d[8], stray]), scene.frames[8])
    assert tracker._layout[0] == 3


def test_xyxy_file_where_xywh_is_expected_is_refused(scene):
    d = scene_dets(scene)
    as_file = {n: v for n, v in enumerate(d, start=1) if len(v)}  # x1, y1, x2, y2 "as xywh"
    with pytest.raises(ValueError, match="look like x1, y1, x2, y2"):
        track_frames(scene.frames, detections=as_file, rng=0)


def test_detections_in_a_smaller_frames_pixels_are_said(scene):
    """Was silent: a 1440x1080 video given its 640x480 det.txt tracked in the top-left corner
    only (boxes too large for the frame are clipped, and said)."""
    d = scene_dets(scene)
    xywh = {n: np.column_stack([v[:, :2], v[:, 2:4] - v[:, :2], v[:, 4:]]) for n, v in
            enumerate(d, start=1) if len(v)}  # fmt: skip
    small = {n: np.column_stack([v[:, :4] * 0.4, v[:, 4:]]) for n, v in xywh.items()}
    frames = scene.frames[:20]
    with pytest.warns(UserWarning, match="top-left .* of the 480x360 frames"):
        track_frames(frames, detections={n: v for n, v in small.items() if n <= 20}, rng=0)
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*top-left")
        track_frames(frames, detections={n: v for n, v in xywh.items() if n <= 20}, rng=0)


@pytest.mark.parametrize(
    ("reach", "hint"), [((767, 575), "about 0.625"), ((700, 500), "about 0.686")]
)
def test_larger_frames_scale_hint_is_a_round_ratio_just_below_the_estimate(
    scene, reach: tuple[int, int], hint: str
):
    """A user report: PETS09's boxes (768x576 pixels) reach 767: the hint was "about 0.626",
    480/767, where the ratio of the image sizes is 0.625. Without seqinfo.ini (frames in
    memory) the estimate from the boxes' reach is an upper bound: a round ratio just below it
    is the one meant; one far below is not named."""
    right, bottom = reach
    boxes = np.array([[600.0, 400, 50, 80, 1], [right - 40.0, bottom - 75.0, 40, 75, 1]])
    dets = {n: boxes.copy() for n in range(1, 31)}  # all 60 boxes wholly outside 480x360
    with pytest.raises(ValueError, match=rf"wholly outside .* {hint} here$"):
        track_frames(scene.frames, detections=dets, rng=0)


def test_detections_in_a_larger_frames_pixels_are_refused(scene):
    """Was a warning only: PETS09's 768x576 det.txt on its 480x360 video, without --det-scale,
    lost half its boxes (wholly outside the frame) and clipped the others, exit 0."""
    d = scene_dets(scene)
    xywh = {n: np.column_stack([v[:, :2], v[:, 2:4] - v[:, :2], v[:, 4:]]) for n, v in
            enumerate(d, start=1) if len(v)}  # fmt: skip
    large = {n: np.column_stack([v[:, :4] * 2.0, v[:, 4:]]) for n, v in xywh.items()}
    with pytest.raises(ValueError, match=r"wholly outside the 480x360 frames .* about 0\.5"):
        track_frames(scene.frames, detections=large, rng=0)
    # a few boxes past the edge (a detector's boxes of people leaving) are no such evidence
    few = {n: v.copy() for n, v in xywh.items()}
    for v in list(few.values())[:5]:
        v[0, 0] = 500.0
    with pytest.warns(UserWarning, match="clipped"):
        run = track_frames(scene.frames[:10], detections={n: v for n, v in few.items() if n <= 10})
    assert run.n_frames == 10


def test_loop_refuses_boxes_in_a_larger_frames_pixels(scene):
    """Was a warning that boxes were clipped (wrong coordinate scale?), and tracks of the
    clipped boxes, while track_frames refused the same boxes: the loop refuses them once 20
    boxes have been given and more than 10 % of them lay wholly outside the frame."""
    d = scene_dets(scene)
    large = [np.column_stack([v[:, :4] * 2.0, v[:, 4:]]) for v in d]
    tracker = pftrack.Tracker(seed=0, prime=0)
    message = (
        r"^dets: \d+ of the \d+ boxes given so far lie wholly outside the 480x360 frame \(they "
        r"reach \d+x\d+\): are they in a larger frame's pixels\? Multiply x1, y1, x2, y2 by the "
        r"frame's size over theirs: at most 0\.5\d* by their reach so far \(e\.g\. 0\.5 for "
        r"960x720, 0\.333 for 1440x1080, 0\.25 for 1920x1440 pixels\)$"
    )
    with pytest.warns(UserWarning, match="clipped"), pytest.raises(ValueError, match=message):
        for k, frame in enumerate(scene.frames):
            tracker.update(large[k], frame)
    assert 0 < tracker.frame_count < 20  # within the first frames, at the 20th box or so
    given = sum(len(v) for v in large[: tracker.frame_count + 1])
    assert given >= 20 and sum(len(v) for v in large[: tracker.frame_count]) < given
    n = tracker.frame_count
    with pytest.raises(ValueError, match="wholly outside"):  # the refused frame changed nothing
        tracker.update(large[n], scene.frames[n])
    assert tracker.frame_count == n
    # the boxes at the frame's scale, and a few past its edge (stray boxes), run on
    few = [v.copy() for v in d]
    for v in [v for v in few if len(v)][9::10]:
        v[0, [0, 2]] = [490.0, 520.0]
    with pytest.warns(UserWarning, match="clipped"):
        run_loop(pftrack.Tracker(seed=0, prime=0), scene.frames, few)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run_loop(pftrack.Tracker(seed=0, prime=0), scene.frames, d)


@pytest.mark.dataset
def test_loop_refuses_pets09_det_txt_unscaled():
    """A user trial: PETS09's det.txt as given (768x576 pixels) on its 480x360 video ran 60
    frames with one warning and 117 wrong rows; the scaled boxes run the whole video
    (test_documented_loop_is_the_cli_byte_for_byte)."""
    folder = dataset("pets09-s2l1")
    by_frame = group_by_frame(read_mot(folder / "det.txt"))
    tracker = pftrack.Tracker(frame_rate=7.0)
    message = (
        r"^dets: 13 of the 21 boxes given so far lie wholly outside the 480x360 frame .* at "
        r"most 0\.692 by their reach so far \(e\.g\. 0\.667 for 720x540, 0\.625 for 768x576, "
        r"0\.5 for 960x720 pixels\)$"
    )
    with pytest.warns(UserWarning, match="clipped"), pytest.raises(ValueError, match=message):
        for n, frame in enumerate(itertools.islice(FrameSource(folder / "video.avi"), 60), 1):
            r = by_frame.get(n, np.zeros((0, 10)))
            tracker.update(xywh_to_xyxy_dets(r[:, [2, 3, 4, 5, 6]]), frame)
    assert tracker.frame_count == 6  # refused at frame 7


def test_boxes_outside_the_frame_are_clipped_once(scene):
    frame = scene.frames[0]
    h, w = frame.shape[:2]
    d = scene_dets(scene)[0]
    extra = np.array([[w + 10, 5, w + 40, 50, 1.0], [-20, h - 30, 15, h + 30, 1.0]])
    dets = np.vstack([extra, d])
    tracker = pftrack.Tracker(seed=0, prime=0)
    with pytest.warns(UserWarning, match="clipped"):
        out = tracker.update(dets, frame)
    assert np.all(out[:, 7] != 0)  # the box wholly outside never matches
    assert np.all((out[:, :4] >= -1) & (out[:, [2]] <= w + 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # warned once per tracker
        tracker.update(dets, scene.frames[1])
    xywh, cls, kept, clipped, flat, inverted, _ = check_boxes_xyxy(dets, (h, w))
    assert clipped and kept[0] == 1 and 0 not in kept and flat == inverted == 0
    np.testing.assert_array_equal(xywh[0], [0, h - 30, 15, 30, 1.0])  # clipped at x = 0, y = h
    inside = np.all((d[:, :2] >= 0) & (d[:, 2:4] <= [w, h]), axis=1)
    assert inside.any()
    np.testing.assert_array_equal(  # boxes inside the frame are untouched
        xywh[1:][inside, :4], np.column_stack([d[:, :2], d[:, 2:4] - d[:, :2]])[inside]
    )


@pytest.mark.parametrize("cols", [4, 5, 6])
def test_boxes_all_inside_the_frame_are_checked_as_any_others(cols):
    # the usual frame (every box with an extent, inside the frame) takes a shorter path: the
    # same arrays as the general one, which one box reaching outside the frame takes
    h, w = 120, 160
    rows = [[-0.0, 0.0, 30, 40, 0.9, 2], [10, 5, 160, 120, 0.4, 0], [3.5, 7.25, 9, 8, 1, 1]]
    dets = np.array(rows)[:, :cols]
    fast = check_boxes_xyxy(dets, (h, w))
    outside = np.vstack([dets, [[-50, 10, -10, 30, 0.5, 1][:cols]]])
    general = check_boxes_xyxy(outside, (h, w))
    assert general.clipped and list(general.kept) == [0, 1, 2]  # the box outside dropped
    assert (fast.clipped, fast.flat, fast.inverted, fast.extent) == (False, 0, 0, 3)
    assert general.extent == 4
    for a, b in zip(fast[:3], general[:3], strict=True):
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes()  # -0.0 made +0.0 by both
    assert not np.signbit(fast.xywh_score[0, 0])


@pytest.mark.parametrize(
    ("dets", "error", "match"),
    [
        (np.ones((2, 7)), ValueError, r"shape \(N, 4\), \(N, 5\) or \(N, 6\)"),
        # empty, but not of an allowed shape (a trial find: accepted as "no detection")
        (np.zeros((3, 0)), ValueError, r"got \(3, 0\)"),
        (np.zeros((0, 7)), ValueError, r"got \(0, 7\)"),
        (np.array([[1.0, 2, np.nan, 4]]), ValueError, "NaN or inf"),
        (np.array([["a", "b", "c", "d"]]), TypeError, "numbers"),
        # rows of different lengths: was NumPy's "setting an array element with a sequence.
        # The requested array has an inhomogeneous shape ...", which named no argument
        (
            [[10.0, 10, 50, 80, 0.9], [10.0, 10, 50]],
            ValueError,
            r"^dets must be a rectangular array of numbers, got rows of different lengths$",
        ),
        # two inverted boxes (one alone is dropped with a warning)
        (
            np.array([[10.0, 10, 5, -4], [20, 20, 15, 8]]),
            ValueError,
            r"^dets row 0 \[10.0, 10.0, 5.0, -4.0\] has x2 < x1 or y2 < y1, as have 2 of the 2 "
            r"boxes given \(x1, y1, x2, y2 expected\)$",
        ),
    ],
)
def test_bad_detections_are_one_line_errors(dets, error, match):
    with pytest.raises(error, match=match):
        pftrack.Tracker().update(dets, np.zeros((30, 40, 3), np.uint8))


@pytest.mark.parametrize(
    "dets",
    [np.array([[10.0, 10, 50, 80, 0.9, 0]]), np.zeros((0, 6), np.float32), [], None],
)
def test_an_image_given_as_dets_says_the_arguments_are_swapped(dets):
    # update(frame, dets), MultiObjectTracker.update's order: was "frame dtype is float64,
    # expected uint8" about the user's uint8 frame (or "frame is list", "frame is NoneType")
    frame = np.zeros((30, 40, 3), np.uint8)
    tracker = pftrack.Tracker()
    with pytest.raises(TypeError) as e:
        tracker.update(frame, dets)
    assert str(e.value) == (
        "Tracker.update(dets, frame): dets is a (30, 40, 3) uint8 array, an image; were the "
        "arguments swapped? (MultiObjectTracker.update takes (frame, detections))"
    )
    assert tracker.frame_count == 0
    tracker.update([], frame)  # the run goes on


def test_options_and_frames():
    with pytest.raises(ValueError, match="frame_rate"):
        pftrack.Tracker(frame_rate=0)
    with pytest.raises(ValueError, match="max_coast"):
        pftrack.Tracker(max_coast=-1.0)
    # absurd spans and rates (a fuzz find: max_coast=1e308 was an OverflowError)
    span = r"max_coast is 1e\+308 s, inf frames at 25 frames/s: more than 100000"
    with pytest.raises(ValueError, match=span):
        pftrack.Tracker(max_coast=1e308)
    with pytest.raises(ValueError, match=r"prime is 5000 s, 1.25e\+05 frames .*more than 100000"):
        pftrack.Tracker(prime=5000.0)
    with pytest.raises(ValueError, match=r"frame_rate is 1e\+308, expected a number in \(0, 1000"):
        pftrack.Tracker(frame_rate=1e308)
    assert pftrack.Tracker(max_coast=4000.0).config.lifecycle.max_coast == 100_000  # the bound
    with pytest.raises(ValueError, match="camera_motion"):
        pftrack.Tracker(camera_motion="sometimes")
    # a user trial: "100" and 1.5 were ValueErrors, and 10**9 named FilterConfig's n_particles
    for wrong in ("100", 1.5, True):
        with pytest.raises(TypeError, match=r"^particles must be an integer in \[1, 1000000\]"):
            pftrack.Tracker(particles=wrong)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^particles is 1000000000, expected an integer in"):
        pftrack.Tracker(particles=10**9)
    with pytest.raises(TypeError, match="uint8"):
        pftrack.Tracker().update(None, np.zeros((30, 40, 3)))
    # the defaults are the command's frame counts at any rate; seconds given become frames
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config

    cli = tracker_config(build_parser().parse_args(["track", "v.avi", "--out", "t.txt"]))
    for rate in (7.0, 25.0, 50.0):
        tracker = pftrack.Tracker(frame_rate=rate)
        assert tracker.config == TrackerConfig() == cli
        assert tracker.prime_frames == 30 and tracker._writer_args[3] == LinkConfig()
    slow = pftrack.Tracker(frame_rate=7.0, max_coast=0.4, prime=1.2)
    assert slow.config.lifecycle.max_coast == 3 and slow.prime_frames == 8
    assert pftrack.Tracker(frame_rate=50.0, max_coast=0.4).config.lifecycle.max_coast == 20


def test_a_frame_rate_as_a_fraction_is_a_number():
    # PyAV gives a stream's rate as a Fraction (stream.average_rate): it was refused, "frame_rate
    # must be a number, got Fraction Fraction(30000, 1001)"
    from fractions import Fraction

    ntsc = Fraction(30000, 1001)
    tracker = pftrack.Tracker(frame_rate=ntsc, max_coast=Fraction(1, 2), prime=1.0)
    assert tracker.frame_rate == float(ntsc)
    assert tracker.config.lifecycle.max_coast == 15 and tracker.prime_frames == 30
    with pytest.raises(ValueError, match=r"^frame_rate is 2000, expected a number in \(0, 1000"):
        pftrack.Tracker(frame_rate=Fraction(2000))
    with pytest.raises(ValueError, match=r"^max_coast 0.5: the joint sampler"):
        pftrack.Tracker(frame_rate=ntsc, sampler="rjmcmc", max_coast=Fraction(1, 2))
    for wrong in ("25", True, None, 25j):  # still not numbers
        with pytest.raises(TypeError, match="^frame_rate must be a number"):
            pftrack.Tracker(frame_rate=wrong)  # type: ignore[arg-type]


def test_every_frame_rate_and_time_takes_a_fraction_as_its_float(scene, tmp_path):
    """A user trial: the Fraction of the test above worked for Tracker's time constants only.
    ``birth_score=Fraction(1, 2)`` and ``FrameSource(path, fps=Fraction(...))`` were refused
    as not numbers, ``VideoWriter`` / ``TrackRenderer`` / ``write_annotated_video`` failed
    with NumPy's "ufunc 'isfinite' not supported", ``make_scene`` stored it as given, and a
    NumPy ``float16`` of seconds overflowed ("RuntimeWarning: overflow encountered in cast")."""
    from fractions import Fraction

    from pftrack.integrations.supervision import SupervisionTracker
    from pftrack.synthetic import make_busy_scene

    ntsc = Fraction(30000, 1001)
    as_float = pftrack.Tracker(frame_rate=float(ntsc), max_coast=0.5, prime=1.0,
                               min_conf=0.25, birth_score=0.5, birth_quantile=0.5)  # fmt: skip
    for kind in (Fraction, np.float64, np.float32, np.float16):
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no overflow in a float16's cast
            t = pftrack.Tracker(
                frame_rate=ntsc if kind is Fraction else kind(float(ntsc)),
                max_coast=kind(1) / 2, prime=kind(1), min_conf=kind(1) / 4,
                birth_score=kind(1) / 2, birth_quantile=kind(1) / 2,
            )  # fmt: skip
        assert t.config == as_float.config and t.prime_frames == as_float.prime_frames
        assert type(t.config.lifecycle.birth_quantile) is float
    assert SupervisionTracker(frame_rate=ntsc).tracker.frame_rate == float(ntsc)
    assert pftrack.Tracker.from_config(frame_rate=ntsc).frame_rate == float(ntsc)
    video = tmp_path / "scene.avi"
    with pftrack.VideoWriter(video, ntsc) as writer:
        for f in scene.frames[:3]:
            writer.write(f)
    assert writer.fps == float(ntsc)
    assert pftrack.FrameSource(video, fps=ntsc).fps == float(ntsc)
    pftrack.write_annotated_video(tmp_path / "a.avi", scene.frames[:3], scene.truth, ntsc)
    renderer = pftrack.TrackRenderer(tmp_path / "r.avi", ntsc)
    renderer.add(scene.frames[0], [])
    renderer.close()
    assert make_scene(n_frames=2, fps=ntsc).fps == float(ntsc)
    assert make_busy_scene("groups", n_frames=2, fps=ntsc).fps == float(ntsc)
    # what is not a real number is refused, naming the argument
    for call, name in ((lambda v: pftrack.VideoWriter(tmp_path / "b.avi", v), "fps"),
                       (lambda v: pftrack.FrameSource(video, fps=v), "fps"),
                       (lambda v: make_scene(n_frames=2, fps=v), "make_scene: fps"),
                       (lambda v: pftrack.Tracker(max_coast=v), "max_coast")):  # fmt: skip
        for wrong in ("25", 2j):
            with pytest.raises(TypeError, match=f"^{name} must be a number"):
                call(wrong)
        with pytest.raises(ValueError, match=f"^{name} is a Fraction beyond a float's range"):
            call(Fraction(10**400))  # named, not printed: 401 digits


def test_no_refine_takes_the_boxes_as_given(scene, tmp_path):
    from pftrack.cli import build_parser
    from pftrack.cli._options import tracker_config

    argv = ["track", "v.avi", "--out", "t.txt", "--detections", "d.txt", "--no-refine"]
    args = build_parser().parse_args(argv)
    config = tracker_config(args)
    assert pftrack.Tracker(refine=False).config == config
    assert not config.refine.enabled and config.refine.leg_fill == TrackerConfig().refine.leg_fill
    dets = scene_dets(scene)
    plain = pftrack.Tracker(refine=False)
    refined = pftrack.Tracker()
    for d, f in zip(dets[:15], scene.frames[:15], strict=True):
        a, b = plain.update(d, f), refined.update(d, f)
    assert plain.tracker.last_mask is None  # no background model ran
    assert refined.tracker.last_mask is not None
    # the same frames through the command with --no-refine give the loop's rows
    assert len(a) and len(b)
    folder = tmp_path / "seq"
    folder.mkdir()
    det_rows = []
    for n, (d, f) in enumerate(zip(dets, scene.frames, strict=True), start=1):
        cv2.imwrite(str(folder / f"{n:06d}.png"), f)
        det_rows += [[n, -1, x1, y1, x2 - x1, y2 - y1, c, -1, -1, -1] for x1, y1, x2, y2, c in d]
    write_mot(tmp_path / "det.txt", np.asarray(det_rows))
    out = tmp_path / "t.txt"
    argv = ["-q", "track", str(folder), "--detections", str(tmp_path / "det.txt")]
    assert main([*argv, "--no-refine", "--out", str(out)]) == 0
    given = load_detections(tmp_path / "det.txt")  # as the command reads the file
    loop = pftrack.Tracker(refine=False)
    for n, f in enumerate(scene.frames, start=1):
        loop.update(xywh_to_xyxy_dets(given.get(n, np.zeros((0, 5)))), f)
    written = tmp_path / "loop.txt"
    write_mot(written, loop.finalize())
    assert written.read_bytes() == out.read_bytes()


def test_builtin_detector_when_dets_is_none(scene):
    tracker = pftrack.Tracker(seed=0)
    tracker.prime(scene.frames[:30])
    outs = [tracker.update(None, f) for f in scene.frames]
    assert sum(len(o) for o in outs) > 0
    assert all(np.all(o[:, 7] == -1) for o in outs)
    assert len(tracker.finalize()) > 0
    with pytest.raises(ValueError, match="before the first update"):
        tracker.prime(scene.frames[:3])


def test_none_after_detections_warns_once_naming_the_frame(scene):
    """Was silent: a loop passing None for "no detections" switched that frame to the
    built-in background-subtraction detector."""
    dets = scene_dets(scene)
    tracker = pftrack.Tracker(seed=0)
    for k in range(10):
        tracker.update(dets[k], scene.frames[k])
    with pytest.warns(UserWarning) as record:
        tracker.update(None, scene.frames[10])
    (w,) = record
    assert str(w.message) == (
        "frame 11: dets=None runs the built-in background-subtraction detector for this "
        "frame, after frames with detections; for a frame without detections give [] or "
        "np.zeros((0, 6))"
    )
    assert w.filename == __file__  # the caller's line
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once a run
        tracker.update(None, scene.frames[11])
        tracker.update(np.zeros((0, 6)), scene.frames[12])  # no detections: no warning
        tracker.update([], scene.frames[13])
        tracker.reset()  # a new run: None from the start is the built-in detector, silently
        for f in scene.frames[:3]:
            tracker.update(None, f)


def test_track_frames_is_the_tracker_loop(scene):
    """track_frames (the CLI's library) and a loop over Tracker agree (priming included)."""
    d = scene_dets(scene)
    as_file = {n: np.column_stack([v[:, :2], v[:, 2:4] - v[:, :2], v[:, 4]]) for n, v in
               enumerate(d, start=1)}  # fmt: skip
    run = track_frames(scene.frames, detections=as_file, rng=5)
    tracker = pftrack.Tracker(seed=5)
    tracker.prime(scene.frames[:30])
    for n, f in enumerate(scene.frames, start=1):
        tracker.update(xywh_to_xyxy_dets(as_file[n]), f)
    np.testing.assert_array_equal(tracker.finalize(), run.rows)


def test_startup_tracks_that_never_reach_min_hits_are_dropped_offline(scene):
    # a box seen in the first two frames only: SORT's convention reports it at once (frames
    # 1 .. min_hits), but it never reaches min_hits matches, so the offline pass drops it
    frames = scene.frames[:12]
    dets = scene_dets(scene)[:12]
    flash = np.array([[5.0, 5.0, 25.0, 45.0, 1.0]])
    dets = [np.vstack([d, flash]) if k < 2 else d for k, d in enumerate(dets)]
    tracker = pftrack.Tracker(frame_rate=25.0, seed=0)
    outs, rows = run_loop(tracker, frames, dets)
    flash_ids = {int(r[4]) for r in outs[0] if r[0] < 30 and r[1] < 30}
    assert len(flash_ids) == 1  # reported online ...
    (flash_id,) = flash_ids
    assert flash_id in tracker.tracker.never_confirmed()
    assert flash_id not in rows[:, 1]  # ... and not in the final rows
    others = {int(i) for o in outs for i in o[:, 4]} - flash_ids
    assert others and others <= set(rows[:, 1].astype(int))  # the walkers all stay
    # without the flash the same run gives the same rows: nothing else changed
    clean = pftrack.Tracker(frame_rate=25.0, seed=0)
    _, rows_clean = run_loop(clean, frames, scene_dets(scene)[:12])
    assert len(rows_clean) == len(rows)


def _lifecycle(**changes):
    return TrackerConfig(lifecycle=dataclasses.replace(TrackerConfig().lifecycle, **changes))


def test_finalize_drops_the_builtin_detectors_nested_boxes():
    """Built-in detector: finalize() leaves out boxes inside a larger one (drop_nested) ..."""
    # people split into fragments (on "present", seed 0, until groups were cut only at a
    # valley of their profile, BlobConfig.split_valley; "groups" seed 1 still has 4)
    busy = make_busy_scene("groups", n_frames=100, rng=1)

    def rows(config, dets=None):
        tracker = pftrack.Tracker.from_config(config, 0)
        tracker.prime(busy.frames[:30])
        for k, f in enumerate(busy.frames):
            tracker.update(None if dets is None else dets[k], f)
        return tracker.finalize()

    life = TrackerConfig().lifecycle
    kept = rows(_lifecycle(nested_inside=None, amodal_share=None))
    assert len(kept) > len(drop_nested(kept, life.nested_inside, life.nested_area))  # some to drop
    np.testing.assert_array_equal(
        rows(_lifecycle(amodal_share=None)), drop_nested(kept, life.nested_inside, life.nested_area)
    )
    # ... but never given detections: a box inside a larger one is then a partly hidden person
    d = scene_dets(busy)
    np.testing.assert_array_equal(rows(TrackerConfig(), d), rows(_lifecycle(nested_inside=None), d))


@pytest.mark.parametrize("anchor", ["side", "centre"])
def test_finalize_completes_partly_seen_people_with_the_builtin_detector(anchor):
    """Built-in detector: finalize() completes short and narrow boxes to the size model's
    person (complete_boxes, after drop_nested) ..."""
    busy = make_busy_scene("present", n_frames=100, rng=0)

    def run(config, dets=None):
        tracker = pftrack.Tracker.from_config(config, 0)
        tracker.prime(busy.frames[:30])
        for k, f in enumerate(busy.frames):
            tracker.update(None if dets is None else dets[k], f)
        return tracker.finalize(), tracker.tracker.detector

    plain, detector = run(_lifecycle(amodal_share=None))
    lines = detector.size_model.coefficients
    assert lines is not None  # the model was fitted on this scene
    done, _ = run(_lifecycle(amodal_share=0.9, amodal_anchor=anchor))
    split = detector.size_model.config.split_ratio
    # ill-posed boxes left alone when the fits over the video disagree (fitagree)
    how = "complete" if detector.size_model.fits_agree(0.9) else "leave"
    expected = complete_boxes(plain, lines, 0.9, anchor, split, busy.height, how)
    assert not np.array_equal(expected, plain)  # some box was completed
    np.testing.assert_array_equal(done, expected)
    # ... but never given detections (a person detector boxes the whole person)
    d = scene_dets(busy)
    np.testing.assert_array_equal(
        run(_lifecycle(amodal_share=0.9), d)[0], run(_lifecycle(amodal_share=None), d)[0]
    )


@pytest.mark.parametrize(
    ("changes", "match"),
    [({"amodal_share": 0.0}, "amodal_share is 0.0"), ({"amodal_share": 1.1}, "amodal_share"),
     ({"amodal_anchor": "top"}, "amodal_anchor is 'top'")],
)  # fmt: skip
def test_amodal_settings_are_checked(changes, match):
    with pytest.raises(ValueError, match=match):
        _lifecycle(**changes)


@pytest.mark.parametrize(
    ("changes", "match"),
    [({"nested_inside": 0.0}, "nested_inside is 0.0"), ({"nested_inside": 1.2}, "nested_inside"),
     ({"nested_area": 0.9}, "nested_area is 0.9"), ({"nested_area": float("nan")}, "nested_area")],
)  # fmt: skip
def test_nested_settings_are_checked(changes, match):
    with pytest.raises(ValueError, match=match):
        _lifecycle(**changes)


def test_no_track_warning_names_min_hits_when_tracks_started():
    # was "the highest detection confidence was 0.9 (min_conf 0, birth_score 0.9)": the box
    # started a track (id 1 every frame), dropped for having fewer than min_hits matches
    frame = np.zeros((120, 160, 3), np.uint8)
    frame[40:80, 60:80] = (0, 0, 255)
    tracker = pftrack.Tracker(refine=False)
    box = np.array([[60.0, 40.0, 80.0, 80.0, 0.9]])
    assert [tracker.update(box, frame)[0, 4] for _ in range(3)] == [1, 1, 1]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert len(tracker.finalize()) == 0
    said = [str(c.message) for c in caught]
    assert said == [
        "no track over 3 frames: 1 track started but none reached min_hits=4 matched frames "
        "(shorter tracks are left out)"
    ]


def test_no_track_warning_is_given_once_for_a_runs_frames():
    """``finalize()`` called twice on the same frames gave the same warning twice (trial63);
    it returns the same rows again without a word, and warns anew after more frames or a reset."""
    frame = np.full((60, 80, 3), 100, np.uint8)
    tracker = pftrack.Tracker()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(3):
            tracker.update(np.zeros((0, 5)), frame)
        first, second = tracker.finalize(), tracker.finalize()
        said = [str(c.message) for c in caught if "no track" in str(c.message)]
        assert said == ["no track over 3 frames: the detections given held no box"]
        assert first.shape == second.shape == (0, 10)
        tracker.update(np.zeros((0, 5)), frame)  # one more frame: a new finding, said
        tracker.finalize()
        tracker.reset()
        tracker.update(np.zeros((0, 5)), frame)
        tracker.finalize()
        tracker.finalize()
    said = [str(c.message) for c in caught if "no track" in str(c.message)]
    assert said[1:] == [
        "no track over 4 frames: the detections given held no box",
        "no track over 1 frame: the detections given held no box",
    ]


def _no_track_said(tracker, frames, dets=None) -> list[str]:
    """Track `frames` (each with `dets`, None: the built-in detector) to an empty finalize();
    the "no track" warnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for f in frames:
            tracker.update(dets, f)
        assert len(tracker.finalize()) == 0
    return [str(c.message) for c in caught if "no track" in str(c.message)]


def test_no_track_warning_of_the_built_in_detector_blames_it():
    # was "no external detection was given", which the user never meant to give
    said = _no_track_said(pftrack.Tracker(seed=0), [np.full((60, 80, 3), 90, np.uint8)] * 5)
    assert said == [
        "no track over 5 frames: the built-in detector found no object (no detection was given)"
    ]


def test_no_track_warning_of_one_frame_says_the_detector_needs_more(scene):
    # a user trial (stop 72): one frame said "found no object", true but no help; the
    # background the detector differences against is learned over frames
    said = _no_track_said(pftrack.Tracker(seed=0), [scene.frames[30]])  # people in it
    assert said == [
        "no track over 1 frame: the built-in detector found no object: it finds objects by "
        "their difference to a background learned over the frames, which one frame cannot "
        "give (give more frames, or a detector's boxes)"
    ]


def test_no_track_warning_says_min_conf_left_the_built_in_detectors_objects_out(scene):
    """A user trial: ``--min-conf 1`` with the built-in detector said it "found no object",
    though it found hundreds and min_conf left every one out."""
    tracker = pftrack.Tracker(seed=0, min_conf=1.5)  # the paper detector's scores reach 1
    tracker.prime(scene.frames)
    said = _no_track_said(tracker, scene.frames)
    assert len(said) == 1
    assert re.fullmatch(
        r"no track over 40 frames: the built-in detector found \d+ objects over the run, "
        r"scored at most [01](\.\d+)?: none reached min_conf 1\.5",
        said[0],
    ), said


def test_no_track_warning_says_min_area_left_the_built_in_detectors_objects_out():
    """A defect trial: a 6x6 object, under min_area=64 pixels, was said to be scored at most
    1 with "none reached min_conf 0" (1 >= 0: min_conf left nothing out)."""
    background = np.random.default_rng(0).integers(60, 120, (120, 160, 3), dtype=np.uint8)
    frames = [background.copy() for _ in range(6)]
    for f in frames[3:]:
        f[40:46, 60:66] = (0, 0, 255)
    for sampler in ("sis", "rjmcmc"):
        said = _no_track_said(pftrack.Tracker(sampler=sampler), frames)
        assert said == [
            "no track over 6 frames: the built-in detector found 3 objects over the run: each "
            "one scoring at least min_conf 0 was under min_area=64 pixels "
            "(LifecycleConfig.min_area)"
        ], sampler


def test_no_track_warning_says_the_blob_filters_left_the_foreground_out():
    """A user trial on hard footage: people 10 px tall (4x10, under the detector's min_area of
    259 px at 480x360) walking across a 480x360 scene were said to be "no object" found."""
    background = np.random.default_rng(0).integers(60, 120, (360, 480, 3), dtype=np.uint8)
    frames = [background.copy() for _ in range(8)]
    for i, f in enumerate(frames[2:]):
        for k in range(3):
            f[100 + 80 * k : 110 + 80 * k, 100 + 3 * i : 104 + 3 * i] = (0, 0, 255)
    said = _no_track_said(pftrack.Tracker(seed=0), frames)
    assert len(said) == 1
    head, pixels, tail = re.split(r"(?<=at most )(\d+)(?= a frame)", said[0])
    assert int(pixels) >= 3 * 40  # three 4x10 people (each region under min_area), trails
    assert head + "N" + tail == (
        "no track over 8 frames: the built-in detector found no object, though its foreground "
        "held pixels on 6 of the 8 frames (at most N a frame): no region passed its blob "
        "filters (BlobConfig: min_area 0.0015 of the frame, 259 pixels at 480x360; height / "
        "width 0.25 to 6; fill 0.2): people too small in the frame, or noise? give a person "
        "detector's boxes (pftrack track --detections; Tracker.update's dets)"
    )


def test_no_track_warning_of_the_joint_sampler_on_the_built_in_detector():
    """A defect trial (``pftrack track`` on a 40x1 image folder, --sampler rjmcmc): objects
    the joint sampler kept none of were said to have "none reached min_conf 0" at score 1.
    Its chain is stubbed to keep nothing here: a real run needs odd footage."""
    background = np.random.default_rng(0).integers(60, 120, (120, 160, 3), dtype=np.uint8)
    frames = [background.copy() for _ in range(6)]
    for i, f in enumerate(frames[2:]):
        f[40:80, 60 + 2 * i : 80 + 2 * i] = (0, 0, 255)
    tracker = pftrack.Tracker(sampler="rjmcmc")
    tracker.tracker._joint.step = lambda *args: []  # type: ignore[method-assign]
    said = _no_track_said(tracker, frames)
    assert said == [
        "no track over 6 frames: the joint sampler (rjmcmc) kept none of the 4 objects the "
        "built-in detector found (each is proposed as a birth; too few frames, or no colour to "
        "weigh them?)"
    ]


def test_no_track_warning_of_the_joint_sampler_names_min_conf():
    """A defect trial: with rjmcmc, detections all below min_conf (logits) were said to be
    proposed as births the sampler kept none of; it never saw them."""
    tracker = pftrack.Tracker(sampler="rjmcmc")
    frame = np.random.default_rng(0).integers(0, 255, (200, 300, 3), dtype=np.uint8)
    said = _no_track_said(tracker, [frame] * 3, np.array([[10, 20, 50, 120, -0.5]]))
    assert said == [
        "no track over 3 frames: the highest detection confidence was -0.5 (min_conf 0, "
        "birth_score 0.9)"
    ]


@pytest.mark.parametrize(
    ("where", "hint"),
    [
        ("no box", "the detections given held no box"),
        ("outside", r"no detection lay inside the frame \(wrong coordinate scale\?\)"),
        # was "the detections given held no box": boxes were given, every one without area
        ("flat", "every detection given was without area or had x2 < x1 or y2 < y1"),
        # was: "the highest detection confidence was 0.95 (... birth_score 0.9)", not the cause
        ("tiny", r"every detection inside the frame was under min_area=64 pixels \(40 left out; "
                 r"LifecycleConfig.min_area\)"),
    ],
)  # fmt: skip
def test_no_track_warning_says_what_the_detections_were(scene, where, hint):
    # was "no external detection was given" for both: detections were given
    w = scene.frames[0].shape[1]
    far = np.array([[w + 10.0, 10.0, w + 30.0, 50.0, 1.0]])
    tiny = np.array([[100.0, 100.0, 105.0, 105.0, 0.95]])
    flat = np.array([[w, 10.0, w, 50.0, 0.9], [30.0, 40.0, 60.0, 40.0, 0.9]])
    box = {"no box": np.zeros((0, 5)), "outside": far, "tiny": tiny, "flat": flat}[where]
    dets = [box] * len(scene.frames)
    if where == "outside":  # under 20 boxes: more are refused (a larger frame's pixels?)
        dets = [box] * 19 + [np.zeros((0, 5))] * (len(scene.frames) - 19)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _, rows = run_loop(pftrack.Tracker(seed=0), scene.frames, dets)
    assert len(rows) == 0
    said = [str(c.message) for c in caught if "no track" in str(c.message)]
    assert len(said) == 1 and re.fullmatch(f"no track over 40 frames: {hint}", said[0]), said


def test_negative_confidences_warn_once_and_min_conf_keeps_them() -> None:
    frame = np.zeros((60, 80, 3), np.uint8)
    frame[::2] = 90  # not blank: the checks below want no other warning
    dets = np.array([[10.0, 10.0, 20.0, 40.0, -1.5], [40.0, 10.0, 50.0, 40.0, 0.8]])
    tracker = pftrack.Tracker(frame_rate=10.0)
    with pytest.warns(UserWarning, match=r"confidence is -1\.5: .*below min_conf 0 .*logits"):
        tracker.update(dets, frame)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # once per run
        tracker.update(dets, frame)
        # a min_conf below the scores given: nothing is dropped, nothing to say
        pftrack.Tracker(frame_rate=10.0, min_conf=-10.0).update(dets, frame)
        pftrack.Tracker(frame_rate=10.0).update(dets[1:], frame)


def test_empty_detections_of_every_allowed_shape_are_no_detection():
    frame = np.zeros((30, 40, 3), np.uint8)
    for empty in (np.zeros(0), np.zeros((0, 4)), np.zeros((0, 5)), np.zeros((0, 6)), []):
        assert pftrack.Tracker().update(empty, frame).shape == (0, 8)


def test_out_of_range_scores_below_min_conf_change_nothing(scene):
    """One ignored negative score must not turn the birth threshold off for the run (a trial
    find: it took PETS09's IDF1 from 79.6 to 66.9), nor a confidence a rounding above 1."""
    dets = scene_dets(scene, scores=(0.5, 1.0))
    _, plain = run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames, dets)
    odd = [d.copy() for d in dets]
    odd[0] = np.vstack([odd[0], [[1.0, 1.0, 9.0, 20.0, -0.5]]])
    tracker = pftrack.Tracker(frame_rate=10.0)
    with pytest.warns(UserWarning, match=r"confidence is -0\.5"):
        _, rows = run_loop(tracker, scene.frames, odd)
    np.testing.assert_array_equal(rows, plain)
    rounded = [d.copy() for d in dets]
    rounded[2][0, 4] = 1.0000001  # a float32 1.0 summed, say
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, rows = run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames, rounded)
    assert len(rows) == len(plain)
    # a score well above 1: said once, then scores are a detector's own scale
    high = [d.copy() for d in dets]
    high[3][:, 4] *= 3.0
    with pytest.warns(UserWarning, match=r"score is .* \(frame 4\): scores above 1"):
        run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames, high)


def test_an_update_that_raises_leaves_the_tracker_as_it_was(scene):
    dets = scene_dets(scene)
    _, plain = run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames, dets)
    tracker = pftrack.Tracker(frame_rate=10.0)
    outs = []
    for k, (d, f) in enumerate(zip(dets, scene.frames, strict=True)):
        if k in (0, 3):  # refused before any state changes: the caller skips and goes on
            with pytest.raises(ValueError, match="NaN or inf"):
                tracker.update(np.array([[1.0, 2, np.nan, 4, 0.9]]), f)
            assert tracker.frame_count == k and tracker.tracker.frame_index == k
        outs.append(tracker.update(d, f))
    np.testing.assert_array_equal(tracker.finalize(), plain)
    # the joint sampler refuses two classes, also before it changes anything
    joint = pftrack.Tracker(frame_rate=10.0, sampler="rjmcmc")
    joint.update(dets[0], scene.frames[0])
    two = np.column_stack([dets[1], np.arange(len(dets[1])) % 2])
    with pytest.raises(ValueError, match="tracks one class"):
        joint.update(two, scene.frames[1])
    assert joint.frame_count == joint.tracker.frame_index == 1
    joint.update(dets[1], scene.frames[1])  # a user trial: the run was dead after a refusal
    assert joint.frame_count == 2


def test_a_refusal_from_inside_the_tracker_leaves_the_run_whole(scene):
    """A user trial: inputs the tracker inside refuses (a frame of another size than the
    primed ones; with rjmcmc, a second class) were refused, and then every later ``update``
    said the run had been interrupted."""
    dets = scene_dets(scene)
    tracker = pftrack.Tracker(frame_rate=10.0)
    small = np.ascontiguousarray(scene.frames[0][: scene.frames[0].shape[0] // 2])
    tracker.prime([small])
    with pytest.raises(ValueError, match="the frames given to prime"):
        tracker.update(dets[0], scene.frames[0])
    tracker.update(dets[0][:0], small)  # the primed size goes on
    assert tracker.frame_count == 1
    joint = pftrack.Tracker(frame_rate=10.0, sampler="rjmcmc", particles=50)
    joint.update(np.column_stack([dets[0], np.zeros(len(dets[0]))]), scene.frames[0])
    with pytest.raises(ValueError, match="class 1 after class 0"):
        joint.update(np.column_stack([dets[1], np.ones(len(dets[1]))]), scene.frames[1])
    for d, f in zip(dets[1:], scene.frames[1:], strict=True):
        joint.update(np.column_stack([d, np.zeros(len(d))]), f)
    assert joint.frame_count == len(scene.frames)


def test_a_sliver_at_the_frames_edge_is_dropped_at_any_working_size():
    """A user trial: with ``max_side``, a box inside the frame whose scaled top lands on the
    working frame's bottom edge was dropped by the tracker inside after the classes were
    matched to the rows: "classes has 2 entries, expected 1", and the run was dead."""
    frame = np.full((480, 640, 3), 90, np.uint8)
    good = [200.0, 150.0, 260.0, 300.0, 0.95]
    # its top on the working frame's bottom edge (scale 333/640); its width 0 once scaled
    # (5e-324 times 256/640 rounds to 0)
    for edge, side in (([100.0, np.nextafter(480.0, 0), 300.0, 480.0, 0.95], 333),
                       ([0.0, 100.0, 5e-324, 200.0, 0.95], 256)):  # fmt: skip
        assert 5e-324 * (256 / 640) == 0.0
        tracker = pftrack.Tracker(frame_rate=25.0, max_side=side)
        for _ in range(6):
            out = tracker.update(np.array([edge, good]), frame)
        assert len(out) == 1 and out[0, 7] == 1  # the good box, by its row


def test_the_joint_sampler_keeps_its_one_class_for_the_run(scene):
    """A user trial: rjmcmc took one class per frame, so class 0 on even frames and 1 on odd
    ones shared identities, and every row said class 0 whatever the class given."""
    dets = scene_dets(scene)
    joint = pftrack.Tracker(frame_rate=10.0, sampler="rjmcmc", particles=50)
    outs = [joint.update(np.column_stack([d, np.full(len(d), 3)]), f)
            for d, f in zip(dets, scene.frames, strict=True)]  # fmt: skip
    classes = np.concatenate([o[:, 6] for o in outs])
    assert len(classes) and set(classes.tolist()) == {3.0}
    mixed = pftrack.Tracker(frame_rate=10.0, sampler="rjmcmc", particles=50)
    mixed.update(np.column_stack([dets[0], np.zeros(len(dets[0]))]), scene.frames[0])
    with pytest.raises(ValueError, match="class 1 after class 0 in earlier frames"):
        mixed.update(np.column_stack([dets[1], np.ones(len(dets[1]))]), scene.frames[1])
    assert mixed.frame_count == 1  # refused before it changed anything


def test_an_update_cut_short_stops_the_run_but_keeps_its_rows(scene):
    """A user trial: Ctrl-C inside ``update`` (a notebook's stop button) after the tracker
    inside had taken the frame left ``frame_count`` one behind; going on from it made
    ``finalize()`` fail on a duplicate (frame, id) and lost the run."""
    dets = scene_dets(scene)
    tracker = pftrack.Tracker(frame_rate=10.0)
    for d, f in zip(dets[:5], scene.frames[:5], strict=True):
        tracker.update(d, f)
    kept = tracker.finalize()
    inner = tracker.tracker.update

    def interrupted(*args, **kwargs):
        inner(*args, **kwargs)
        raise KeyboardInterrupt

    tracker.tracker.update = interrupted  # type: ignore[method-assign]
    with pytest.raises(KeyboardInterrupt):
        tracker.update(dets[5], scene.frames[5])
    del tracker.tracker.update
    with pytest.raises(RuntimeError, match=r"frame 6 was interrupted .* frames 1-5, reset\(\)"):
        tracker.update(dets[6], scene.frames[6])
    np.testing.assert_array_equal(tracker.finalize(), kept)
    tracker.reset()
    _, plain = run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames, dets)
    _, again = run_loop(tracker, scene.frames, dets)
    np.testing.assert_array_equal(again, plain)


def test_normalised_boxes_are_said_once(scene):
    """A user trial: a detector's x1y1x2y2n boxes (0..1) were tracked as sub-pixel boxes in
    the frame's corner, without a word."""
    dets = scene_dets(scene)
    h, w = scene.frames[0].shape[:2]
    tracker = pftrack.Tracker(frame_rate=10.0)
    match = r"frame 1: every detection box lies within \[0, 1\]"
    with pytest.warns(UserWarning, match=match) as rec:
        for d, f in zip(dets[:5], scene.frames[:5], strict=True):
            tracker.update(d / [w, h, w, h, 1.0], f)
    assert sum("normalised" in str(r.message) for r in rec) == 1
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*normalised")
        run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames[:5], dets[:5])


def test_integer_detections_with_truncated_confidences_are_said_once(scene):
    """A user trial: ``dets.astype(int)`` turned every confidence into 0, without a word."""
    dets = scene_dets(scene, scores=(0.5, 0.95))
    tracker = pftrack.Tracker(frame_rate=10.0)
    with pytest.warns(
        UserWarning, match=r"^frame 1: detections given as integers \(int64\)"
    ) as rec:
        for d, f in zip(dets[:3], scene.frames[:3], strict=True):
            tracker.update(d.astype(np.int64), f)
    assert sum("as integers" in str(r.message) for r in rec) == 1
    with warnings.catch_warnings():  # integers with their scores kept (0 or 1): no word
        warnings.filterwarnings("error", message=".*as integers")
        ones = [np.c_[d[:, :4].astype(np.int64), np.ones((len(d), 1), np.int64)] for d in dets[:10]]
        run_loop(pftrack.Tracker(frame_rate=10.0), scene.frames[:10], ones)


def test_a_detectors_raw_candidates_are_said_once():
    """A user trial: a detector's raw output before NMS (YOLO gives about 8400 boxes a frame)
    took minutes a frame in the dense association, without a word."""
    rng = np.random.default_rng(0)
    frame = rng.integers(0, 256, (360, 480, 3), dtype=np.uint8)

    def dets(n: int) -> np.ndarray:
        x, y = rng.uniform(0, 440, n), rng.uniform(0, 300, n)
        return np.c_[x, y, x + 20, y + 50, np.full(n, 0.9)]

    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*detections in one frame")
        pftrack.Tracker(frame_rate=10.0).update(dets(1000), frame)
    tracker = pftrack.Tracker(frame_rate=10.0)
    with pytest.warns(UserWarning, match=r"^frame 1: 1001 detections in one frame; .*non-max"):
        tracker.update(dets(1001), frame)
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*detections in one frame")
        tracker.update(dets(1001), frame)  # once a run


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"birth_score": 2}, r"^birth_score is 2.0, expected a value in \[0, 1\]$"),
        ({"birth_quantile": -0.5}, r"^birth_quantile is -0.5, expected a value in \[0, 1\]$"),
    ],
)
def test_birth_gates_out_of_range_are_named_as_the_arguments(kwargs, match):
    """A user trial: ``Tracker(birth_score=2)`` said "LifecycleConfig: birth_score is 2.0",
    naming a class the caller never touched."""
    with pytest.raises(ValueError, match=match):
        pftrack.Tracker(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"link": "x"}, TypeError, "link must be a LinkConfig or None, got str"),
        ({"smoother": "x"}, TypeError, "smoother must be a BoxSmoother or None, got str"),
        ({"config": {}}, TypeError, "config must be a TrackerConfig, got dict"),
        ({"frame_rate": -5}, ValueError, r"frame_rate is -5, expected a number in \(0, "),
        ({"frame_rate": "25"}, TypeError, "frame_rate must be a number"),
        ({"prime_frames": True}, ValueError, "prime_frames is True"),
    ],
)
def test_from_config_checks_its_arguments_at_once(kwargs, error, match):
    """Were accepted: ``link="x"`` failed at ``finalize()`` on a missing attribute."""
    with pytest.raises(error, match=match):
        pftrack.Tracker.from_config(**kwargs)


def test_prime_of_what_is_not_iterable_is_a_type_error():
    with pytest.raises(TypeError, match="prime takes an iterable of frames .* got NoneType"):
        pftrack.Tracker().prime(None)  # type: ignore[arg-type]


def test_prime_reads_no_more_than_prime_frames(scene):
    read = []

    def frames():
        for k, f in enumerate(scene.frames):
            read.append(k)
            yield f

    tracker = pftrack.Tracker(frame_rate=10.0, prime=0.5)  # 5 frames
    tracker.prime(frames())
    assert read == [0, 1, 2, 3, 4]
    read.clear()
    pftrack.Tracker(frame_rate=10.0, prime=0.0).prime(frames())
    assert read == []


def _one_buffer(frames, buffer=None):
    """`frames` read into one reused array, as ``cap.read(buffer)`` loops read them."""
    buffer = np.empty_like(frames[0]) if buffer is None else buffer
    for f in frames:
        np.copyto(buffer, f)
        yield buffer


@pytest.mark.parametrize("memmap", [False, True])
def test_prime_from_one_reused_buffer_is_the_prime_of_the_frames(scene, memmap, tmp_path):
    """A trial find: ``prime`` kept the arrays a generator yielded, so a loop reading every
    frame into one buffer primed the background from its last frame 30 times, not from the
    median of 30 frames (silently other tracks; with ``max_side`` scaling it was right). A
    memmap buffer is taken as a new array sharing its memory, not as the same object."""
    shape = scene.frames[0].shape
    buffer = np.memmap(tmp_path / "frame", np.uint8, "w+", shape=shape) if memmap else None

    def rows(frames):
        tracker = pftrack.Tracker()
        tracker.prime(frames)
        for f in scene.frames:
            tracker.update(None, f)
        return tracker.finalize()

    once = rows(_one_buffer(scene.frames, buffer))
    np.testing.assert_array_equal(once, rows(list(scene.frames)))


def test_multi_object_tracker_prime_from_one_reused_buffer(scene):
    """As above, for ``MultiObjectTracker.prime``, which took the generator as a list."""

    def boxes(frames):
        tracker = pftrack.MultiObjectTracker(rng=0)
        tracker.prime(frames)
        return [(t.id, *t.box_xywh) for f in scene.frames for t in tracker.update(f)]

    assert boxes(_one_buffer(scene.frames)) == boxes(list(scene.frames))


def test_prime_and_update_of_other_sizes_are_refused_by_the_tracker():
    tracker = pftrack.Tracker()
    tracker.prime([np.zeros((100, 100, 3), np.uint8)] * 3)
    with pytest.raises(ValueError, match=r"frame is 48x36, the frames given to prime\(\) 100x100"):
        tracker.update(None, np.zeros((36, 48, 3), np.uint8))


@pytest.mark.parametrize("size", [(360, 640), (540, 960)])
def test_prime_and_update_of_other_sizes_are_refused_with_max_side(size):
    """A trial find: with ``max_side`` the check compared the scaled sizes, so 1280x720 prime
    frames and 640x360 or 960x540 frames to track (all 640x360 once scaled) were taken: the
    background of another picture, silently."""
    tracker = pftrack.Tracker(max_side=640)
    tracker.prime([np.zeros((720, 1280, 3), np.uint8)] * 3)
    message = rf"^frame is {size[1]}x{size[0]}, the frames given to prime\(\) 1280x720 \(one "
    with pytest.raises(ValueError, match=message):
        tracker.update(None, np.zeros((*size, 3), np.uint8))
    assert tracker.frame_count == 0
    tracker.update(None, np.zeros((720, 1280, 3), np.uint8))  # the primed size is taken


def test_score_options_must_be_finite_numbers():
    with pytest.raises(ValueError, match="birth_score is nan, expected a finite number"):
        pftrack.Tracker(birth_score=float("nan"))
    with pytest.raises(TypeError, match="min_conf must be a number, got str"):
        pftrack.Tracker(min_conf="0.5")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="birth_score is inf"):
        TrackerConfig(lifecycle=_lifecycle(birth_score=np.inf))


@pytest.mark.parametrize(
    ("given", "named"),
    [
        ({"max_coast": 1.0}, "max_coast 1"),
        ({"birth_score": 0.5}, "birth_score 0.5"),
        ({"birth_quantile": None}, "birth_quantile None"),
        ({"max_coast": 0.4, "birth_score": 0.2}, "max_coast 0.4, birth_score 0.2"),
    ],
)
def test_joint_sampler_refuses_the_lifecycle_options_it_ignores(given, named):
    """A defect trial: ``pftrack track`` refuses --max-coast and --birth-score with --sampler
    rjmcmc (its chain keeps and starts tracks by its own existence probabilities), but
    Tracker(sampler="rjmcmc", ...) took them and tracked as without them."""
    with pytest.raises(ValueError, match=rf"^{re.escape(named)}: the joint sampler \(rjmcmc\)"):
        pftrack.Tracker(sampler="rjmcmc", **given)
    pftrack.Tracker(sampler="sis", **given)  # used there


def test_joint_sampler_counts_the_objects_it_started(scene):
    tracker = pftrack.Tracker(frame_rate=10.0, sampler="rjmcmc")
    for d, f in zip(scene_dets(scene)[:6], scene.frames[:6], strict=True):
        tracker.update(d, f)
    assert tracker.tracker.tracks_started > 0


def test_no_track_warning_of_the_joint_sampler_does_not_blame_confidences():
    tracker = pftrack.Tracker(sampler="rjmcmc")
    frame = np.zeros((200, 300, 3), np.uint8)
    tracker.update(np.array([[10, 20, 50, 120, 0.95]]), frame)
    with pytest.warns(UserWarning, match="dets=None runs the built-in"):  # on purpose
        tracker.update(None, frame)
    with pytest.warns(RuntimeWarning, match=r"joint sampler \(rjmcmc\) kept no object"):
        tracker.finalize()


def test_a_detection_file_without_scores_is_said(tmp_path):
    """Six fields a row (no score) gave every box the score 1 silently: --birth-score was then
    a no-op."""
    (tmp_path / "six.txt").write_text("1,-1,10,10,20,40\n2,-1,11,10,20,40\n")
    with pytest.warns(UserWarning, match="six.txt: no score column .* every detection scores 1"):
        got = load_detections(tmp_path / "six.txt")
    assert [float(r[0, 4]) for r in got.values()] == [1.0, 1.0]
    (tmp_path / "seven.txt").write_text("1,-1,10,10,20,40,0.8\n")
    assert float(load_detections(tmp_path / "seven.txt")[1][0, 4]) == 0.8  # no warning


def test_a_detection_file_with_ids_is_said(tmp_path):
    """A file whose id column holds ids (another tracker's output, a ground truth) given as
    detections was read with its ids ignored without a word."""
    rows = "1,7,10,10,20,40,1\n1,-1,50,10,20,40,1\n2,7,11,10,20,40,1\n"
    (tmp_path / "tracks.txt").write_text(rows)
    with pytest.warns(UserWarning) as caught:
        got = load_detections(tmp_path / "tracks.txt")
    said = [str(w.message) for w in caught]
    assert said == [
        f"{tmp_path / 'tracks.txt'}: 2 of 3 rows have a track id, not -1 (the first: id 7 in "
        "frame 1): a tracks file? Read as detections: the ids are ignored, the tracker makes "
        "its own"
    ]
    assert [len(r) for r in got.values()] == [2, 1]  # every box still read
    (tmp_path / "det.txt").write_text("1,-1,10,10,20,40,0.8\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_detections(tmp_path / "det.txt")  # id -1: no warning


def test_detections_after_a_video_that_ended_early_are_said(tmp_path):
    """A truncated video (its header promised more frames) ended the run with its detections of
    the frames never decoded dropped without a word.

    (This test used a 1-frame list of frames, which the frame-count check let through; a real
    truncated file is what the warning is for.)"""
    full = make_scene(n_frames=20, rng=0).write_video(tmp_path / "full.avi")
    cut = tmp_path / "cut.avi"
    cut.write_bytes(full.read_bytes()[: full.stat().st_size // 2])  # the header still says 20
    box = np.array([[40.0, 30.0, 20.0, 40.0, 0.9]])
    dets = {f: box for f in range(1, 21)}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = track_frames(FrameSource(cut), detections=dets)
    said = [str(w.message) for w in caught if issubclass(w.category, UserWarning)]
    n = run.n_frames
    assert 1 < n < 20
    assert any(f"detections of {20 - n} frames after the video's last frame {n}" in m for m in said)


@pytest.mark.filterwarnings("ignore:no track over:RuntimeWarning")
@pytest.mark.parametrize("n", [1, 2, 5])
def test_detections_past_the_frame_count_are_refused_at_every_length(n):
    """Was: a 1-frame video ran with a warning (exit 0), 2 frames and more were refused, and
    the message did not say what to do."""
    frames = [np.full((120, 160, 3), 90, np.uint8)] * n
    box = np.array([[40.0, 30.0, 20.0, 40.0, 0.9]])
    dets = {f: box for f in range(1, 201)}
    which = "frame 1" if n == 1 else f"frames 1-{n}"
    message = (
        f"detections go up to frame 200 but the video has {n} frame{'s' * (n > 1)}: they belong "
        f"to a longer video; keep only the rows of {which} (e.g. awk -F, '$1<={n}' det.txt"
    )
    with pytest.raises(ValueError, match="^" + re.escape(message)):
        track_frames(frames, detections=dets)
    # the rows of frames 1..n (and empty frames after them) are taken
    dets = {f: box if f <= n else np.zeros((0, 5)) for f in range(1, 201)}
    assert track_frames(frames, detections=dets).n_frames == n


class _UnknownLength(list):
    """Frames whose count is unknown, as a camera's or a raw stream's (``len`` 0)."""

    def __len__(self) -> int:
        return 0


@pytest.mark.filterwarnings("ignore:no track over:RuntimeWarning")
def test_detections_of_a_source_of_unknown_length_are_not_checked_up_front():
    frame = np.full((120, 160, 3), 90, np.uint8)
    box = np.array([[40.0, 30.0, 20.0, 40.0, 0.9]])
    with pytest.warns(UserWarning, match="detections of 2 frames after the video's last frame 1"):
        run = track_frames(_UnknownLength([frame]), detections={1: box, 2: box, 3: box})
    assert run.n_frames == 1


_BOX = np.array([[40.0, 30.0, 20.0, 40.0, 0.9]])


@pytest.mark.parametrize(
    ("detections", "error", "message"),
    [
        ("det.txt", TypeError, "detections is a path ('det.txt'), expected the dict {frame: "
         "(k, 5) [left, top, w, h, score]} of its boxes: load the file first with "
         "pftrack.load_detections(path)"),
        (Path("det.txt"), TypeError, "detections is a path ('det.txt')"),
        ([_BOX], TypeError, "detections must be a dict {frame: (k, 5) [left, top, w, h, score] "
         "array}, as pftrack.load_detections returns, got list"),
        ({1: _BOX[:, :3]}, ValueError, "detections[1] must have shape (k, 5) [left, top, w, h, "
         "score] (or (k, 4)), got (1, 3)"),
        ({1: _BOX[0]}, ValueError, "detections[1] must have shape (k, 5) "),
        ({"1": _BOX}, TypeError, "detections key '1' is str, expected an int frame number"),
        ({1.0: _BOX}, TypeError, "detections key 1.0 is float, expected an int frame number"),
        ({True: _BOX}, TypeError, "detections key True is bool"),
        ({0: _BOX, 1: _BOX}, ValueError, "detections key 0 is not a frame number in "
         "1..2147483647: frames are 1-based, as in det.txt and load_detections (0-based keys "
         "would put every box one frame late; add 1 to each)"),
        ({-3: _BOX}, ValueError, "detections key -3 is not a frame number in 1..2147483647: "),
        ({2: _BOX, 1: [[1, 2, 3], [1, 2]]}, ValueError, "detections[1] must be a rectangular "
         "array of numbers"),
        ({1: [["a", "b", "c", "d"]]}, TypeError, "detections[1] must hold real numbers"),
        ({1: np.array([[40.0, 30, np.nan, 40, 0.9]])}, ValueError, "detections[1] row 0 "
         "contains NaN or inf"),
        ({1: np.array([[40.0, 30, -20, 40, 0.9]])}, ValueError, "detections[1] row 0 [40.0, "
         "30.0, -20.0, 40.0]: negative box width or height (left, top, w, h)"),
    ],
)  # fmt: skip
def test_track_frames_checks_detections_first(detections, error, message):
    """Were: AttributeError ('str' object has no attribute 'items') for a path or a list,
    IndexError for a (k, 3) array, a TypeError from ``<=`` for string keys, and 0-based or
    negative keys accepted silently, every box one frame late (frame 0's dropped)."""
    frames = [np.full((120, 160, 3), 90, np.uint8)] * 3

    def no_frames():  # the checks come before any frame is read
        raise AssertionError("a frame was read")
        yield

    for source in (frames, no_frames()):
        with pytest.raises(error, match="^" + re.escape(message)):
            track_frames(source, detections=detections)


@pytest.mark.filterwarnings("ignore:no track over:RuntimeWarning")
def test_track_frames_takes_detections_as_load_detections_gives_them(tmp_path):
    """NumPy int keys, lists, (k, 4) rows without score, empty values: the rows of the file."""
    scene = make_scene(n_frames=12, rng=0)
    det = tmp_path / "det.txt"
    write_mot(det, np.column_stack([scene.truth[:, 0], -np.ones(len(scene.truth)),
                                    scene.truth[:, 2:]]))  # fmt: skip
    loaded = load_detections(det)
    expected = track_frames(scene.frames, detections=loaded, rng=0).rows
    as_lists = {np.int64(f): v.tolist() for f, v in loaded.items()}
    as_lists[len(scene.frames) + 5] = []  # an empty frame past the end is no box
    np.testing.assert_array_equal(
        track_frames(scene.frames, detections=as_lists, rng=0).rows, expected
    )
    scored_1 = {f: np.column_stack([v[:, :4], np.ones(len(v))]) for f, v in loaded.items()}
    np.testing.assert_array_equal(
        track_frames(scene.frames, detections={f: v[:, :4] for f, v in loaded.items()},
                     rng=0).rows,
        track_frames(scene.frames, detections=scored_1, rng=0).rows,
    )  # fmt: skip


def test_cli_refuses_detections_of_a_longer_video_for_a_1_frame_video(tmp_path, capsys):
    """The trial's ``track pets_short1.avi --detections det_200.txt``: was a warning, exit 0."""
    video = make_scene(n_frames=1, rng=0).write_video(tmp_path / "one.avi")
    det = tmp_path / "det.txt"
    det.write_text("".join(f"{f},-1,40,30,20,40,0.9\n" for f in range(1, 201)))
    out = tmp_path / "t.txt"
    assert main(["-q", "track", str(video), "--detections", str(det), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "pftrack track: error: detections go up to frame 200 but the video has 1 frame: they "
        "belong to a longer video; keep only the rows of frame 1 (e.g. awk -F, '$1<=1' det.txt"
    ), err
    assert len(err.splitlines()) == 1 and not out.exists()


def test_cli_counts_the_frames_of_a_video_whose_header_says_too_few(tmp_path, capsys):
    """An AVI whose header says 5 of its 20 frames: its detections of frames 6-20 were refused
    ("detections go up to frame 20 but the video has 5 frames"), the run not made."""
    from tests.io.test_video import _header_count

    video = _header_count(make_scene(n_frames=20, rng=0).write_video(tmp_path / "v.avi"), 5)
    det = tmp_path / "det.txt"
    det.write_text("".join(f"{f},-1,40,30,20,40,0.9\n" for f in range(1, 21)))
    out = tmp_path / "t.txt"
    assert main(["-q", "track", str(video), "--detections", str(det), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "its header says 5 frames but it holds 20 (counted)" in err, err
    assert read_mot(out)[:, 0].max() == 20
    det.write_text("".join(f"{f},-1,40,30,20,40,0.9\n" for f in range(1, 31)))
    assert main(["-q", "track", str(video), "--detections", str(det), "--out", str(out)]) == 2
    assert "detections go up to frame 30 but the video has 20 frames" in capsys.readouterr().err


def test_cli_says_detections_of_a_turned_videos_stored_frames_are_so(tmp_path, capsys):
    """A phone's portrait video (stored 96x64, shown 64x96) and boxes a detector found on its
    stored frames: was refused as "in a larger frame's pixels? Scale them with --det-scale"."""
    from tests.io.test_video import turned_mp4

    frames = make_scene(n_frames=25, width=96, height=64, rng=0).frames
    video = turned_mp4(tmp_path / "v.mp4", frames, 90)
    det = tmp_path / "det.txt"
    det.write_text("".join(f"{f},-1,70,20,12,30,0.9\n" for f in range(1, 26)))
    out = tmp_path / "t.txt"
    assert main(["-q", "track", str(video), "--detections", str(det), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (
        "pftrack track: error: 25 of 25 detection boxes lie wholly outside the 64x96 frames "
        "(they reach 82x50), and all fit 96x64: the video is stored 96x64 and turned 270 "
        "degrees clockwise by its rotation metadata, as players, FFmpeg and OpenCV show it "
        "and pftrack reads it; run the detector on the frames as shown (OpenCV's VideoCapture "
        "turns them), not on the stored ones\n"
    ), err
    assert not out.exists()


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_output_boxes_may_reach_past_the_frame_as_documented():
    """A user trial found boxes out of the frame (x2 = 482.7 on a 480-wide video) while the
    input is clipped: the output is the filters' estimate, documented so (with the clip to do
    before cropping), not clipped (that would change the tracking numbers)."""
    scene = make_scene(n_frames=60, rng=2)
    h, w = scene.frames[0].shape[:2]
    tracker = pftrack.Tracker()
    by_frame = group_by_frame(scene.truth)
    for k, frame in enumerate(scene.frames, start=1):
        r = by_frame.get(k, np.zeros((0, 10)))
        tracker.update(xywh_to_xyxy_dets(np.column_stack([r[:, 2:6], np.ones(len(r))])), frame)
    rows = tracker.finalize()
    x1, y1 = rows[:, 2], rows[:, 3]
    x2, y2 = x1 + rows[:, 4], y1 + rows[:, 5]
    past = (x1 < 0) | (y1 < 0) | (x2 > w) | (y2 > h)
    assert past.any()  # as documented: not clipped
    assert ((x1 < w) & (y1 < h) & (x2 > 0) & (y2 > 0)).all()  # none wholly outside
    # the documented clip keeps every box inside, with area
    cx1, cx2 = np.clip(x1, 0, w), np.clip(x2, 0, w)
    cy1, cy2 = np.clip(y1, 0, h), np.clip(y2, 0, h)
    assert ((cx2 > cx1) & (cy2 > cy1)).all()
    from pftrack.integrations.supervision import SupervisionTracker

    for doc in (
        pftrack.Tracker.update.__doc__,
        pftrack.Tracker.finalize.__doc__,
        SupervisionTracker.update_with_detections.__doc__,
        SupervisionTracker.finalize.__doc__,
    ):
        assert "not clipped" in " ".join(str(doc).split())


def test_one_tracker_in_two_threads_at_once_raises_not_crashes(scene):
    # was: a segfault (the C++ background model reallocated under another thread) or a mix of
    # two runs' frames ("duplicate rows" from finalize)
    import threading

    dets = scene_dets(scene)
    tracker = pftrack.Tracker()
    inside, leave = threading.Event(), threading.Event()
    real = tracker._tracker.update

    def held(*args, **kwargs):  # the first thread waits inside update
        inside.set()
        leave.wait(10)
        return real(*args, **kwargs)

    tracker._tracker.update = held
    first = threading.Thread(target=tracker.update, args=(dets[0], scene.frames[0]))
    first.start()
    assert inside.wait(10)
    for method, args in (
        ("update", (dets[0], scene.frames[0])),
        ("finalize", ()),
        ("reset", ()),
        ("prime", ([scene.frames[0]],)),
        # a trial find: read the writer's rows while the other thread appended them (a block
        # moved, rows of np.empty garbage or 1024 rows missing), as the docs say it raises
        ("settled_rows", ()),
    ):
        with pytest.raises(RuntimeError, match=rf"^Tracker\.{method}: this Tracker is in use by "):
            getattr(tracker, method)(*args)
    leave.set()
    first.join()
    del tracker._tracker.update
    assert tracker.frame_count == 1  # the first thread's frame went in, the refused ones not
    tracker.update(dets[1], scene.frames[1])  # free again
    assert tracker.frame_count == 2


def test_background_model_refuses_a_second_thread():
    # the C++ guard under every path that shares a model (PaperDetector, MultiObjectTracker)
    import threading

    from pftrack._core import BackgroundModel

    rng = np.random.default_rng(0)
    frames = [rng.integers(0, 256, (720, 1280, 3), dtype=np.uint8) for _ in range(2)]
    model = BackgroundModel()
    model.apply(frames[0])
    errors: list[str] = []

    def work() -> None:
        for k in range(150):
            try:
                model.apply(frames[k % 2], bins=False)
            except RuntimeError as e:
                errors.append(str(e))

    threads = [threading.Thread(target=work) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors  # the two threads met inside apply (its pass runs without the GIL)
    assert set(errors) == {
        "BackgroundModel.apply: the object is in use by another thread (use one per thread, "
        "or a lock around it)"
    }
    model.apply(frames[0])  # still usable
    assert model.background.shape == (720, 1280, 3)


def test_a_tracker_copies_and_pickles_before_its_first_update(scene):
    import copy
    import pickle

    dets = scene_dets(scene)
    for clone in (copy.deepcopy, lambda t: pickle.loads(pickle.dumps(t))):
        a = pftrack.Tracker()
        b = clone(a)
        for k in range(5):
            np.testing.assert_array_equal(
                a.update(dets[k], scene.frames[k]), b.update(dets[k], scene.frames[k])
            )


@pytest.mark.parametrize("options", [{}, {"sampler": "mh"}, {"refine": False}])
@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
def test_a_copy_mid_run_is_a_checkpoint(scene, options, how):
    # was: TypeError (the C++ background model and bins could not be copied) after one update
    import copy
    import pickle

    dets = scene_dets(scene)
    for given in (True, False):
        a = pftrack.Tracker(**options)
        for k in range(12):
            a.update(dets[k] if given else None, scene.frames[k])
        b = copy.deepcopy(a) if how == "deepcopy" else pickle.loads(pickle.dumps(a))
        for k in range(12, len(scene.frames)):
            np.testing.assert_array_equal(
                a.update(dets[k] if given else None, scene.frames[k]),
                b.update(dets[k] if given else None, scene.frames[k]),
            )
        np.testing.assert_array_equal(a.finalize(), b.finalize())


def test_bins_copy_and_pickle():
    import copy
    import pickle

    from pftrack._core import BinnedImage

    bins = np.random.default_rng(0).integers(-1, 110, (30, 40)).astype(np.int16)
    image = BinnedImage(bins, 110)
    for clone in (copy.copy, copy.deepcopy, lambda b: pickle.loads(pickle.dumps(b))):
        c = clone(image)
        assert c is not image and c.n_bins == 110
        np.testing.assert_array_equal(c.bins, bins)


def test_crossings_without_the_smoother_are_refused():
    # was: accepted silently, where the CLI refuses --crossings on --no-smooth
    with pytest.raises(ValueError, match=r"^crossings=True needs the smoother"):
        pftrack.Tracker(crossings=True, smooth=False)
    pftrack.Tracker(crossings=False, smooth=False)


def test_the_joint_sampler_counts_ids_from_1(scene):
    # was: id 0 in the rows (MOTChallenge ids count from 1, as the other samplers' do)
    dets = scene_dets(scene)
    tracker = pftrack.Tracker(sampler="rjmcmc")
    for k in range(20):
        tracker.update(dets[k], scene.frames[k])
    rows = tracker.finalize()
    assert len(rows) and rows[:, 1].min() >= 1


def test_track_frames_names_every_bootstrap_it_takes():
    # the message left out "auto", the default; prime_frames=0 took any name
    from pftrack.tracking import track_frames

    for prime in (30, 0):
        with pytest.raises(
            ValueError, match="bootstrap mode is 'sprad', expected one of auto, spread"
        ):
            track_frames([], bootstrap="sprad", prime_frames=prime)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("source", "kind"),
    [((f for f in ()), "generator"), (iter([]), "list_iterator"), (0, "int"), (None, "NoneType"),
     (b"frames", "bytes")],
)  # fmt: skip
def test_track_frames_names_a_source_it_cannot_read(source, kind):
    # were Python's "object of type 'generator' has no len()", "'int' object is not
    # iterable", and for bytes "prime frame is int"
    from pftrack.tracking import track_frames

    with pytest.raises(TypeError) as e:
        track_frames(source, show_progress=False)  # type: ignore[arg-type]
    assert str(e.value).startswith(
        f"track_frames: source is {kind}, expected a path, a FrameSource or a sequence of frames"
    )


@pytest.mark.parametrize("shape", [(60, 80, 3), (60, 80)])
@pytest.mark.parametrize("dets", [None, {1: np.array([[10.0, 10.0, 20.0, 40.0, 0.9]])}])
def test_track_frames_of_one_frame_says_to_put_it_in_a_list(shape, dets):
    # was: its rows taken for frames, "prime frame must have shape (H, W, 3) (BGR), got
    # (80, 3): a grey frame? cv2.cvtColor(...)", which names neither the frame nor the cure
    from pftrack.tracking import track_frames

    with pytest.raises(TypeError) as e:
        track_frames(np.zeros(shape, np.uint8), detections=dets, show_progress=False)
    assert str(e.value).startswith(
        f"track_frames: source is one {shape} frame, expected a sequence of frames: "
        "track_frames([frame])"
    )


@pytest.mark.parametrize("shape", [(), (5,), (2, 6, 8, 3, 1)])
def test_track_frames_names_an_array_that_is_not_frames(shape):
    # were: "len() of unsized object" (0-d), and rows of numbers taken for frames ("prime
    # frame is float64 ...") or 5-d frames
    from pftrack.tracking import track_frames

    with pytest.raises(TypeError) as e:
        track_frames(np.zeros(shape, np.uint8), show_progress=False)
    assert str(e.value) == (
        f"track_frames: source is an array of shape {shape}, expected a sequence of frames: a "
        "(K, H, W, 3) uint8 array or a list of (H, W, 3) frames"
    )


def _blank_messages(record: list[warnings.WarningMessage]) -> list[str]:
    return [str(w.message) for w in record if "is blank" in str(w.message)]


def test_a_blank_first_frame_warns_once_a_run() -> None:
    dets = np.array([[10.0, 10.0, 50.0, 90.0, 0.9]])
    tracker = pftrack.Tracker(frame_rate=25.0)
    # an encoded black frame is not all zeros: levels within 2 of each other count as blank
    grey = np.zeros((120, 160, 3), np.uint8)
    grey[::2] = 2
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        for _ in range(3):
            tracker.update(dets, grey)
    (message,) = _blank_messages(record)
    assert message.startswith("frame 1 is blank (every pixel within 2 levels")
    assert "colour filters and box refinement have nothing to see" in message
    # a fade-in from black is the user's own footage, not a mistake (trial61: the advice
    # "placeholder frames? give the real ones" alone was wrong for it)
    assert "a video that starts black is fine" in message
    tracker.reset()  # a new run: said again
    with pytest.warns(UserWarning, match="frame 1 is blank"):
        tracker.update(dets, np.zeros((120, 160, 3), np.uint8))


def test_a_picture_or_a_later_blank_frame_does_not_warn(scene) -> None:
    dets = np.array([[10.0, 10.0, 50.0, 90.0, 0.9]])
    dim = np.zeros((120, 160, 3), np.uint8)
    dim[60:, :, 1] = 3  # a dark frame with one step of 3 levels: a picture, not a placeholder
    runs = {"scene": [scene.frames[0], np.zeros_like(scene.frames[0])], "dim": [dim]}
    for frames in runs.values():
        tracker = pftrack.Tracker(frame_rate=25.0)
        with warnings.catch_warnings(record=True) as record:
            warnings.simplefilter("always")
            for frame in frames:  # the scene's second frame is black: only frame 1 is looked at
                tracker.update(dets, frame)
        assert _blank_messages(record) == []


def _loop_under(action, make, frames, dets):
    """Every ``update``'s output (None where a warning made an error raised) and the rows.

    `action` is the warnings filter ("error" or "ignore"); `make` makes the tracker.
    """
    tracker = make()
    outs, raised = [], []
    with warnings.catch_warnings():
        warnings.simplefilter(action)
        for d, f in zip(dets, frames, strict=True):
            try:
                outs.append(tracker.update(d, f))
            except Warning as w:  # the frame is taken whole before a warning is given
                outs.append(None)
                raised.append(str(w))
        rows = tracker.finalize()
    return outs, rows, raised, tracker


def test_a_warning_made_an_error_leaves_the_tracker_usable(scene):
    """A user trial: under ``python -W error`` the low-confidence warnings, the moving-camera
    warning and the grey-video warning were raised after the tracker had changed, so every
    later ``update`` was refused as interrupted ("the update of frame 1 was interrupted")."""
    from tests.tracking.test_camera import _panned

    dets = scene_dets(scene)
    grey = [np.repeat(f.mean(axis=2, keepdims=True).astype(np.uint8), 3, axis=2)
            for f in scene.frames]  # fmt: skip
    cases = {
        "a detection confidence is -0.5": (scene.frames, [np.column_stack(
            [d[:, :4], np.where(np.arange(len(d)) == 0, -0.5, d[:, 4])]) for d in dets]),
        "a detection score is 3": (scene.frames, [np.column_stack(
            [d[:, :4], d[:, 4] * 3]) for d in dets]),
        "the camera moves": (_panned(), [None] * 30),
        "the video is grey": (grey, dets),
    }  # fmt: skip
    for said, (frames, given) in cases.items():

        def make():
            return pftrack.Tracker(frame_rate=10.0)

        outs, rows, raised, tracker = _loop_under("error", make, frames, given)
        plain, plain_rows, _, _ = _loop_under("ignore", make, frames, given)
        # the pan also differs from the background everywhere: the noise warning, raised too
        raised = [r for r in raised if not r.startswith("noisy or changing video")]
        assert len(raised) == 1 and raised[0].startswith(said), (said, raised)
        assert tracker.frame_count == len(frames)  # every frame taken, the run whole
        assert len(plain_rows) > 0
        np.testing.assert_array_equal(rows, plain_rows)
        for out, ref in zip(outs, plain, strict=True):
            if out is not None:
                np.testing.assert_array_equal(out, ref)


def test_a_warning_made_an_error_leaves_the_multi_object_tracker_whole(scene):
    """As for Tracker: MultiObjectTracker warned of a score above 1 after it had counted the
    frame and before it had tracked it, so the frame's detections started no track; and its
    warnings named the line above the caller's (``stacklevel`` one too many)."""
    dets = [np.column_stack([d[:, :2], d[:, 2:4] - d[:, :2], d[:, 4] * 3])
            for d in scene_dets(scene)]  # fmt: skip

    def run(action):
        tracker = pftrack.MultiObjectTracker(rng=0)
        said, ids = [], []
        with warnings.catch_warnings():
            warnings.simplefilter(action)
            for d, f in zip(dets, scene.frames, strict=True):
                try:
                    tracker.update(f, d)
                except UserWarning as w:
                    said.append(str(w))
                ids.append(sorted(t.id for t in tracker.tracks))
        return tracker, said, ids

    tracker, said, ids = run("error")
    plain, _, plain_ids = run("ignore")
    assert len(said) == 1 and said[0].startswith("a detection score is 3")
    assert tracker.frame_index == plain.frame_index == len(scene.frames)
    assert ids == plain_ids and len(ids[0]) > 0  # frame 1's detections started its tracks
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pftrack.MultiObjectTracker(rng=0).update(scene.frames[0], dets[0])
    assert [Path(w.filename).name for w in caught] == [Path(__file__).name]


def test_a_frames_warnings_made_errors_are_all_given(scene):
    """A user trial: under ``-W error`` a frame with a box without area and a negative
    confidence raised the first warning only; the second, said once a run, was never given."""
    tracker = pftrack.Tracker(frame_rate=10.0)
    dets = np.array([[50.0, 50, 50, 80, 0.9], [100, 100, 130, 180, -0.4]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="^1 detection box without area") as raised:
            tracker.update(dets, scene.frames[0])
        if sys.version_info >= (3, 11):  # add_note
            assert raised.value.__notes__ == [
                "UserWarning: a detection confidence is -0.4: confidences below min_conf 0 are "
                "ignored (logits? give probabilities in [0, 1], or set min_conf)"
            ]
        tracker.update(dets, scene.frames[1])  # each said once a run: the run goes on
    assert tracker.frame_count == 2


def test_finalize_does_not_complete_a_person_entering_through_the_top_edge():
    """Regression (edges trial): a walker entering from the top of make_scene's seed 2 (three
    walkers, no perspective) came out of finalize() with boxes 2 737 px tall in a 360 px
    frame, and walker 1 with boxes up to 525 px (MOTA 93.3 -> 9.4): the size model's height
    slope there is 1.07, so the person "whose head is at" row 0 is 2 700 px tall. A box at
    the top edge has its top cut by the frame, not at a head, and no completed person may
    stand below the frame's bottom."""
    from pftrack.synthetic import _paste, _sprite

    scene = make_scene(n_frames=120, n_walkers=3, rng=2, occluder=False)
    gen = np.random.default_rng(102)
    sprites = [
        _sprite(30, 75, (40, 180, 40), (40, 40, 40), (120, 160, 210), p, gen) for p in (0, 1)
    ]
    truth = [scene.truth]
    for f in range(10, 121):  # 3 px a frame down from above the frame, from frame 10
        box = _paste(
            scene.frames[f - 1], *sprites[((f - 10) // 3) % 2], 300.0, -37.5 + 3 * (f - 10)
        )
        if box is not None:
            truth.append(np.array([[f, 4, *box, 1, -1, -1, -1]], float))
    gt = np.vstack(truth)
    rows = track_frames(scene.frames, rng=0).rows
    assert rows[:, 5].max() <= scene.height, rows[:, 5].max()
    walker = gt[gt[:, 1] == 4]
    found = [any(iou_xywh(g[2:6], r[2:6]) >= 0.5 for r in rows[rows[:, 0] == g[0]]) for g in walker]
    assert np.mean(found) >= 0.85, np.mean(found)  # 100 of 110 (born at frame 21); was 34
    assert evaluate_mot(gt, rows).mota >= 0.7  # amodal_share=None: 0.933; was 0.094


def test_finalize_leaves_ill_posed_boxes_when_the_size_fits_disagree():
    """`make_scene` seed 26 (`python -m experiments.demo_seeds`): the size model's fits read two
    walkers one behind the other as perspective (slopes -0.33 to 0.95 over the video), and the
    last fit (0.954) completed walkers' 85 px boxes to people of 206 px (MOTA 39.5). The fits
    disagree (`PersonSizeModel.fits_agree`), so ``finalize()`` leaves the boxes whose head row
    cannot give a height: MOTA 65.1 (docs/detection.md, 'fitagree')."""
    scene = make_scene(n_frames=150, rng=26)
    rows = track_frames(scene.frames, rng=0).rows
    assert evaluate_mot(scene.truth, rows).mota >= 0.6
