"""With the video, a hole between two neighbours under one id is left unfilled (issue 12, stop 72).

A tracker that hands an id to the nearest object leaves a hole whose jump is plausible (two
people walking side by side), so :func:`pftrack.recovery.fill.jump_holes` fills it. With the
video, :func:`pftrack.recovery.fill.swap_holes` compares the colours of the hole's two sides
with the other objects at the same two frames: when each side looks more like another object
than like the other side, the hole is left (docs/recovery.md, "A hole between two neighbours").
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from pftrack.io.mot import write_mot
from pftrack.particle_filter.colour import bhattacharyya_distance, box_histograms, hsv_bins
from pftrack.recovery import fill_gaps
from pftrack.recovery.fill import (
    JUMP_FACTOR,
    SWAP_FACTOR,
    SWAP_FLOOR,
    jump_holes,
    swap_holes,
    swap_note,
)
from pftrack.recovery.linking import filled_mask
from pftrack.synthetic import make_scene

RED, BLUE = (30, 30, 220), (220, 60, 30)  # BGR shirts of the two walkers


def _walkers(n_frames: int = 24) -> tuple[list[np.ndarray], np.ndarray]:
    """Two walkers side by side (40 px apart, 4 px a frame), red and blue, on a textured floor.

    Returns the BGR frames and the true rows: id 1 the red walker, id 2 the blue one.
    """
    rng = np.random.default_rng(0)
    floor = rng.integers(90, 150, (200, 320, 1), dtype=np.uint8).repeat(3, axis=2)
    frames, rows = [], []
    for f in range(1, n_frames + 1):
        image = floor.copy()
        for tid, colour, top in ((1, RED, 60), (2, BLUE, 100)):
            left = 20 + 4 * f
            image[top : top + 30, left : left + 20] = colour
            rows.append([f, tid, left, top, 20, 30, 1, -1, -1, -1])
        frames.append(image)
    return frames, np.array(rows, dtype=np.float64)


def _handed_over(rows: np.ndarray, hole: range = range(10, 14)) -> np.ndarray:
    """The frames of `hole` missing, and ids 1 and 2 swapped after it (each to its neighbour)."""
    r = rows[~np.isin(rows[:, 0], list(hole))].copy()
    late = r[:, 0] > hole[-1]
    r[late, 1] = 3 - r[late, 1]
    return r


def test_a_hand_over_to_the_neighbour_is_caught_with_the_video() -> None:
    frames, truth = _walkers()
    rows = _handed_over(truth)
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    holes = np.flatnonzero((r[1:, 1] == r[:-1, 1]) & (np.diff(r[:, 0]) > 1))
    assert len(holes) == 2
    assert np.all(jump_holes(r, holes) < JUMP_FACTOR)  # a plausible jump: gate71 fills it
    filled, report = fill_gaps(rows, "linear")
    assert (report.n_gaps, report.n_jumps, report.n_swaps) == (2, 0, 0)
    assert np.all(swap_holes(r, holes, frames) > SWAP_FACTOR)
    filled, report = fill_gaps(rows, "linear", frames=frames)
    assert (report.n_gaps, report.n_filled_rows, report.n_swaps) == (0, 0, 2)
    assert report.largest_swap > SWAP_FACTOR
    assert np.array_equal(filled, rows[np.lexsort((rows[:, 1], rows[:, 0]))])  # nothing drawn
    said = swap_note(report.n_swaps, report.largest_swap)
    assert said.startswith("2 holes left unfilled: each side looks more like another object")
    assert said in str(report) and report.describe().endswith(said)


def test_the_same_walkers_across_a_hole_are_filled() -> None:
    frames, truth = _walkers()
    rows = truth[~np.isin(truth[:, 0], [10, 11, 12, 13])]  # the hole, no hand-over
    filled, report = fill_gaps(rows, "linear", frames=frames)
    assert (report.n_gaps, report.n_filled_rows, report.n_swaps) == (2, 8, 0)
    assert filled_mask(filled).sum() == 8


def test_a_walker_behind_the_lamp_post_is_not_refused() -> None:
    """make_scene's walkers cross its lamp post: their rows behind it dropped, the sides half
    hidden, five walkers (two crossing each other) in the frames."""
    scene = make_scene(n_frames=120, rng=0)
    assert scene.occluder is not None
    x, _, w, _ = scene.occluder
    rows = scene.truth
    centre = rows[:, 2] + 0.5 * rows[:, 4]
    rows = rows[(centre < x - 5) | (centre > x + w + 5)]  # hidden: the truth's boxes dropped
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    holes = np.flatnonzero((r[1:, 1] == r[:-1, 1]) & (np.diff(r[:, 0]) > 1))
    assert len(holes) >= 3
    ratio = swap_holes(r, holes, scene.frames)
    assert np.count_nonzero(ratio) == len(holes)  # every hole judged
    assert ratio.max() < SWAP_FACTOR
    _, with_video = fill_gaps(rows, "linear", frames=scene.frames)
    _, without = fill_gaps(rows, "linear")
    assert with_video.n_swaps == 0 and with_video.n_gaps == without.n_gaps == len(holes)


def _reference(r: np.ndarray, holes: np.ndarray, frames: list[np.ndarray]) -> np.ndarray:
    """A plain loop: each box's histogram on its own, every other box of the two frames."""

    def hist(i: int) -> np.ndarray:
        x, y, w, h = r[i, 2:6]
        image = hsv_bins(frames[int(r[i, 0]) - 1])
        return box_histograms(image, [[x + w / 2, y + h / 2, w, h]])[0]

    out = np.zeros(len(holes))
    for k, e in enumerate(holes):
        a, b = hist(e), hist(e + 1)
        near_b = [hist(i) for i in range(len(r)) if r[i, 0] == r[e + 1, 0] and r[i, 1] != r[e, 1]]
        near_a = [hist(i) for i in range(len(r)) if r[i, 0] == r[e, 0] and r[i, 1] != r[e, 1]]
        near_b = [h for h in near_b if h.sum() > 0]
        near_a = [h for h in near_a if h.sum() > 0]
        if a.sum() == 0 or b.sum() == 0 or not near_a or not near_b:
            continue
        d = bhattacharyya_distance(b, a)[0]
        m_a = min(bhattacharyya_distance(h, a)[0] for h in near_b)
        m_b = min(bhattacharyya_distance(h, b)[0] for h in near_a)
        out[k] = d / max(m_a, m_b, SWAP_FLOOR)
    return out


def test_swap_holes_matches_a_plain_reference() -> None:
    scene = make_scene(n_frames=60, rng=1)
    rows = scene.truth[np.random.default_rng(1).random(len(scene.truth)) >= 0.3]
    rows = _handed_over(rows, range(25, 28))  # ids 1 and 2 swapped too
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    holes = np.flatnonzero((r[1:, 1] == r[:-1, 1]) & (np.diff(r[:, 0]) > 1))
    assert len(holes) > 10
    got = swap_holes(r, holes, scene.frames)
    np.testing.assert_allclose(got, _reference(r, holes, scene.frames), rtol=1e-12)
    assert np.count_nonzero(got) > 10
    # a hole past the end of the frames is not judged (nothing read, nothing refused)
    assert np.all(swap_holes(r, holes, scene.frames[:1]) == 0)


def test_deterministic_and_independent_of_row_order() -> None:
    frames, truth = _walkers()
    rows = _handed_over(truth)
    first, rep1 = fill_gaps(rows, frames=frames)
    shuffled = rows[np.random.default_rng(3).permutation(len(rows))]
    second, rep2 = fill_gaps(shuffled, frames=frames)
    assert np.array_equal(first, second)
    assert (rep1.n_swaps, rep1.largest_swap) == (rep2.n_swaps, rep2.largest_swap) != (0, 0.0)


def test_bad_input_is_refused_as_before() -> None:
    frames, _ = _walkers(2)
    with pytest.raises(TypeError, match="fill_gaps: frames must be a sequence"):
        fill_gaps([[1, 1, 0, 0, 5, 5], [3, 1, 0, 0, 5, 5]], frames=5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"fill_gaps: tracks must have shape \(M, 6..10\)"):
        fill_gaps(np.zeros((2, 3)), frames=frames)
    with pytest.raises(ValueError, match="duplicate"):
        fill_gaps([[1, 1, 0, 0, 5, 5], [1, 1, 0, 0, 5, 5]], frames=frames)


def test_recover_link_video_says_it_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from pftrack.cli import main
    from pftrack.io.video import FrameSequence

    frames, truth = _walkers()
    video = tmp_path / "walkers"  # an image folder: the colours as drawn
    video.mkdir()
    import cv2

    for k, image in enumerate(frames, start=1):
        cv2.imwrite(str(video / f"{k:06d}.png"), image)
    src = tmp_path / "handed.txt"
    write_mot(src, _handed_over(truth), exact=True)
    with FrameSequence(video) as seq:
        _, report = fill_gaps(_handed_over(truth), frames=seq)
    assert report.n_swaps == 2
    out_file = tmp_path / "r.txt"
    argv = ["recover", str(src), "--out", str(out_file), "--link", "--video", str(video)]
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # as outside the test suite (which makes them errors)
        assert main([*argv, "--explain"]) == 0
    out = capsys.readouterr()
    said = swap_note(report.n_swaps, report.largest_swap)
    assert out.err == f"pftrack recover: warning: {src}: {said}\n"
    assert out.out.rstrip().endswith(said)  # --explain's last line
    assert main(["-q", "recover", str(src), "--out", str(tmp_path / "n.txt")]) == 0  # no video
    assert capsys.readouterr().err == ""
    # --video without --link: the fill's check alone (was refused: "used only by --link")
    alone = tmp_path / "alone.txt"
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        assert main(["recover", str(src), "--out", str(alone), "--video", str(video)]) == 0
    assert capsys.readouterr().err == f"pftrack recover: warning: {src}: {said}\n"
    assert np.array_equal(np.loadtxt(alone, delimiter=","), np.loadtxt(out_file, delimiter=","))
