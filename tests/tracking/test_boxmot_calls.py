"""A BoxMOT loop runs unchanged: ``update(dets, img, embs)``, BoxMOT's three arguments.

BoxMOT's trackers take ``update(dets, img, embs=None)``, the embeddings of a ReID model for
its appearance trackers (its motion-only ones ignore them). ``Tracker.update`` took two
arguments: a BoxMOT loop that passed its embeddings failed with Python's ``takes 3
positional arguments but 4 were given``. They are taken now, not used, and said once a run.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import pftrack
from pftrack.synthetic import make_scene


@pytest.fixture(scope="module")
def scene() -> pftrack.Scene:
    return make_scene(n_frames=12, n_walkers=3, rng=1)


def _dets(scene: pftrack.Scene, frame: int) -> np.ndarray:
    r = scene.truth[scene.truth[:, 0] == frame]
    return np.column_stack([r[:, 2], r[:, 3], r[:, 2] + r[:, 4], r[:, 3] + r[:, 5],
                            np.full(len(r), 0.95), np.zeros(len(r))])  # fmt: skip


def _embs(dets: np.ndarray) -> np.ndarray:
    return np.random.default_rng(0).random((len(dets), 512), dtype=np.float32)


def test_embeddings_are_taken_and_change_nothing(scene):
    plain, boxmot = pftrack.Tracker(), pftrack.Tracker()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for k, frame in enumerate(scene.frames, start=1):
            dets = _dets(scene, k)
            expected = plain.update(dets, frame)
            np.testing.assert_array_equal(boxmot.update(dets, frame, _embs(dets)), expected)
    said = [str(w.message) for w in caught if "embs" in str(w.message)]
    assert said == [
        "Tracker.update: embs (appearance embeddings) are not used: pftrack tells objects "
        "apart by their colour in the frame and their motion"
    ]
    assert caught[0].filename == __file__  # the user's line, not pftrack's
    np.testing.assert_array_equal(boxmot.finalize(), plain.finalize())


def test_embs_none_by_keyword_says_nothing(scene):
    tracker = pftrack.Tracker()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tracker.update(_dets(scene, 1), scene.frames[0], embs=None)


def test_the_warning_comes_once_a_run(scene):
    tracker = pftrack.Tracker()
    for _run in range(2):  # reset() starts a new run
        with pytest.warns(UserWarning, match="embs"):
            tracker.update(_dets(scene, 1), scene.frames[0], _embs(_dets(scene, 1)))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            tracker.update(_dets(scene, 2), scene.frames[1], _embs(_dets(scene, 2)))
        tracker.reset()


def test_a_bad_frame_is_refused_before_the_embeddings_are_said(scene):
    tracker = pftrack.Tracker()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(TypeError, match="frame dtype is float32"):
            tracker.update(
                _dets(scene, 1), scene.frames[0].astype(np.float32), _embs(_dets(scene, 1))
            )
    with pytest.warns(UserWarning, match="embs"):  # not spent by the refused call
        tracker.update(_dets(scene, 1), scene.frames[0], _embs(_dets(scene, 1)))


@pytest.mark.parametrize(
    ("dets", "embs", "error", "message"),
    [
        (3, np.zeros((2, 512)), ValueError, r"embs has shape \(2, 512\), expected 3 rows, one per"),
        (3, np.zeros((4, 512)), ValueError, r"embs has shape \(4, 512\), expected 3 rows"),
        (0, np.zeros((1, 512)), ValueError, r"embs has shape \(1, 512\), expected 0 rows"),
        (3, np.float32(1.0), TypeError, "embs is float32, expected a NumPy array with one row"),
        (3, np.array(1.0), ValueError, r"embs has shape \(\), expected 3 rows"),
        (None, np.array(1.0), ValueError, r"embs has shape \(\), expected \(N, D\)$"),
        (3, [[0.0]] * 3, TypeError, "^Tracker.update: embs is list, expected a NumPy array"),
        (3, "reid", TypeError, "embs is str"),
    ],
    ids=["fewer", "more", "no-dets", "scalar", "0-d", "0-d-no-dets", "list", "str"],
)
def test_embeddings_boxmot_would_refuse_are_refused(scene, dets, embs, error, message):
    """A user trial: embs of another row count than dets were taken without a word (BoxMOT's
    ReID trackers fail on them); refused before the tracker takes the frame."""
    boxes = np.array([[10, 10, 40, 60, 0.9, 0], [60, 10, 90, 60, 0.9, 0], [20, 40, 50, 90, 0.8, 0]])
    tracker = pftrack.Tracker()
    with pytest.raises(error, match=message) as e:
        tracker.update(None if dets is None else boxes[:dets], scene.frames[0], embs)
    assert "\n" not in str(e.value) and tracker.frame_count == 0
    with pytest.warns(UserWarning, match="embs"):  # matching rows still run, said once a run
        tracker.update(boxes, scene.frames[0], np.zeros((3, 512)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tracker.update(boxes[:0], scene.frames[1], np.zeros((0, 512)))  # none, as a list too
        tracker.update(boxes.tolist(), scene.frames[2], np.zeros((3, 512), np.float32))
        tracker.update(boxes, scene.frames[3], None)
    assert tracker.frame_count == 4


# BoxMOT's keywords (apinames, 6 December): ``update(dets=..., img=..., embs=...)`` failed with
# Python's ``unexpected keyword argument 'img'``; the frame is taken under either name, once.


def test_boxmots_keywords_give_the_positional_calls_tracks(scene):
    plain, keywords = pftrack.Tracker(), pftrack.Tracker()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # embs' own warning, said above
        for k, frame in enumerate(scene.frames, start=1):
            dets = _dets(scene, k)
            expected = plain.update(dets, frame)
            got = keywords.update(dets=dets, img=frame, embs=_embs(dets))
            np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(keywords.finalize(), plain.finalize())


def test_the_frame_by_its_own_keyword_still_runs(scene):
    tracker = pftrack.Tracker()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert tracker.update(dets=_dets(scene, 1), frame=scene.frames[0]).shape[1] == 8


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda t, d, f: t.update(d, f, img=f), "the frame is given twice, as frame and as img"),
        (lambda t, d, f: t.update(dets=d, frame=f, img=f), "the frame is given twice"),
        (lambda t, d, f: t.update(dets=d), r"no frame given: update\(dets, frame\), or img="),
        (lambda t, d, f: t.update(d), "no frame given"),
        (lambda t, d, f: t.update(d, image=f), "unexpected keyword argument 'image'"),
        (lambda t, d, f: t.update(detections=d, img=f), "unexpected keyword argument 'detect"),
        (lambda t, d, f: t.update(d, img=None), "^img is NoneType, expected"),
        (lambda t, d, f: t.update(d, img=f.astype(float)), "^img dtype is float64"),
    ],
    ids=["twice", "twice-keywords", "none", "none-positional", "image", "detections",
         "img-None", "img-float"],
)  # fmt: skip
def test_a_frame_given_twice_or_not_at_all_is_a_one_line_type_error(scene, call, message):
    tracker = pftrack.Tracker()
    with pytest.raises(TypeError, match=message) as e:
        call(tracker, _dets(scene, 1), scene.frames[0])
    assert "\n" not in str(e.value)
    with warnings.catch_warnings():  # refused before the tracker took anything
        warnings.simplefilter("error")
        tracker.update(_dets(scene, 1), img=scene.frames[0])
    assert tracker.frame_count == 1
