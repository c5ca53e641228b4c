"""Colour in the offline pass: ``smooth_tracks(..., frames=...)`` (stop 73, an option, off).

With the video's frames, the tracker's offline pass (:func:`pftrack.tracking.smooth_tracks`)
links with the linker's colour term and leaves a hole whose sides each look more like another
object than like each other (:func:`pftrack.recovery.fill.swap_holes`). Measured on
PETS09-S2L1, TUD-Campus and the synthetic scenes it is not the default (docs/recovery.md,
"Colour in the offline pass").
"""

from __future__ import annotations

import numpy as np

from pftrack.recovery.fill import side_frames
from pftrack.recovery.linking import (
    FLAG_COLUMN,
    BoxColours,
    LinkConfig,
    link_frames,
    link_tracklets,
)
from pftrack.tracking import smooth_tracks
from tests.recovery.test_hand72_swap import _handed_over, _walkers
from tests.recovery.test_off73_one_pass import _behind_post, _Counted, _fragments

HOLE = range(10, 14)


def _rows_in(out: np.ndarray, frames: range) -> np.ndarray:
    return out[np.isin(out[:, 0], list(frames))]


def test_a_hand_over_between_two_colours_is_left_with_the_frames() -> None:
    """Red and blue walkers side by side, their ids swapped across a 4-frame hole (a tracker
    handing each id to its neighbour): without colour the pass draws both paths across; with
    the frames both holes stay, nothing is drawn in them, and the boxes are still smoothed."""
    frames, truth = _walkers()
    rows = _handed_over(truth, HOLE)
    plain = smooth_tracks(rows)
    assert len(_rows_in(plain, HOLE)) == 2 * len(HOLE)  # filled: the hand-over is plausible
    coloured = smooth_tracks(rows, frames=frames)
    assert len(_rows_in(coloured, HOLE)) == 0
    assert not np.any(coloured[:, FLAG_COLUMN] == 1)
    assert len(coloured) == len(rows)
    # outside the hole the pass is the same: its boxes smoothed, ids kept (not linked across)
    assert np.array_equal(coloured[:, :2], rows[np.lexsort((rows[:, 1], rows[:, 0]))][:, :2])


def test_the_same_walker_across_an_occlusion_is_still_filled() -> None:
    frames, truth = _walkers()
    rows = truth[~np.isin(truth[:, 0], list(HOLE))]  # both hidden, ids kept
    coloured = smooth_tracks(rows, frames=frames)
    assert np.array_equal(coloured, smooth_tracks(rows))
    assert len(_rows_in(coloured, HOLE)) == 2 * len(HOLE)


def test_walkers_behind_the_lamp_post_are_filled_and_linked_alike() -> None:
    """make_scene's walkers: their rows behind the lamp post dropped (holes), and each piece
    after a long hole a new id (fragments for the linker): with the frames, every hole the
    pass fills without colour is filled, and read through one decode the result is the
    same (:class:`~pftrack.recovery.linking.BoxColours`)."""
    scene, rows = _behind_post()
    plain = smooth_tracks(rows)
    coloured = smooth_tracks(rows, frames=scene.frames)
    assert np.array_equal(coloured, plain)
    assert (plain[:, FLAG_COLUMN] == 1).sum() > 0
    cfg = LinkConfig()
    colours = BoxColours(scene.frames, rows, link_frames(rows, cfg) | side_frames(rows, 30))
    assert np.array_equal(smooth_tracks(rows, frames=colours, link=cfg), coloured)


def test_deterministic_and_independent_of_row_order() -> None:
    frames, truth = _walkers()
    rows = _handed_over(truth, HOLE)
    once = smooth_tracks(rows, frames=frames)
    shuffled = rows[np.random.default_rng(1).permutation(len(rows))]
    assert np.array_equal(smooth_tracks(shuffled, frames=frames), once)
    assert np.array_equal(smooth_tracks(rows, frames=frames), once)


def test_the_pass_decodes_once_and_links_with_colour() -> None:
    """Fragments and short holes (the one-pass test's scene): the pass asks for each frame
    once, in increasing order, and gives what the linker and the fill give reading the
    frames themselves."""
    frames, rows = _fragments()
    counted = _Counted(frames)
    out = smooth_tracks(rows, frames=counted)
    assert counted.asked and counted.asked == sorted(set(counted.asked))
    cfg = LinkConfig()
    linked, mapping = link_tracklets(rows, cfg, frames)
    assert mapping and np.array_equal(np.unique(out[:, 1]), np.unique(linked[:, 1]))
    # nothing read beforehand: the linker and the fill bin the frames they ask for themselves
    own = BoxColours(frames, rows, ())
    assert np.array_equal(smooth_tracks(rows, frames=own), out)
