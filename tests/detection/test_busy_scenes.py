"""make_busy_scene: seeded, truthful scenes of the busy-scene failures."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.synthetic import BUSY_SCENES, make_busy_scene, make_scene


@pytest.mark.parametrize("kind", BUSY_SCENES)
def test_seeded_and_truth_inside_the_frame(kind: str) -> None:
    a, b = make_busy_scene(kind, n_frames=30), make_busy_scene(kind, n_frames=30)
    assert all(np.array_equal(x, y) for x, y in zip(a.frames, b.frames, strict=True))
    np.testing.assert_array_equal(a.truth, b.truth)
    t = a.truth
    assert len(t) and t[:, 0].min() == 1 and t[:, 0].max() <= 30
    assert np.all(t[:, 2] >= 0) and np.all(t[:, 3] >= 0)
    assert np.all(t[:, 2] + t[:, 4] <= 480) and np.all(t[:, 3] + t[:, 5] <= 360)


def test_present_everyone_in_view_from_frame_one_and_still_at_first() -> None:
    sc = make_busy_scene("present", n_frames=20)
    first = sc.truth[sc.truth[:, 0] == 1]
    assert len(first) == 6
    tenth = sc.truth[sc.truth[:, 0] == 10]
    np.testing.assert_allclose(tenth[:, 2:6], first[:, 2:6], atol=1)  # all stand until 15
    # perspective: lower feet, taller people
    foot, h = first[:, 3] + first[:, 5], first[:, 5]
    assert np.corrcoef(foot, h)[0, 1] > 0.9


def test_groups_walk_shoulder_to_shoulder() -> None:
    sc = make_busy_scene("groups", n_frames=40)
    f = sc.truth[sc.truth[:, 0] == 15]
    boxes = f[np.argsort(f[:, 2]), 2:6]
    gaps = boxes[1:, 0] - (boxes[:-1, 0] + boxes[:-1, 2])
    assert (gaps < 0).sum() >= 1  # at least two silhouettes overlap: one blob


def test_overhead_is_grey_with_one_size_everywhere() -> None:
    sc = make_busy_scene("overhead", n_frames=10)
    assert all(np.array_equal(f[..., 0], f[..., 1]) for f in sc.frames)
    whole = sc.truth[(sc.truth[:, 2] > 0) & (sc.truth[:, 3] > 0)]
    whole = whole[(whole[:, 2] + whole[:, 4] < 480) & (whole[:, 3] + whole[:, 5] < 360)]
    assert np.ptp(whole[:, 5]) <= 1 and np.ptp(whole[:, 4]) <= 2


def test_bad_kind_raises_and_make_scene_is_unchanged() -> None:
    with pytest.raises(ValueError, match="kind"):
        make_busy_scene("crowd")
    with pytest.raises(ValueError, match="n_frames"):
        make_busy_scene("groups", n_frames=0)
    sc = make_scene(n_frames=5)
    assert len(sc.frames) == 5 and sc.occluder is not None
