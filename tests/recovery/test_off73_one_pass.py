"""``recover --link --video`` decodes its video once for the linker and the fill (stop 73).

The linker's colour term reads the frames of fragment ends and the fill's swap rule those of
the holes' sides (:func:`pftrack.recovery.fill.swap_holes`); both used to read the video in
a pass of their own. :class:`pftrack.recovery.linking.BoxColours` reads the union of their
frames first, in one pass, and answers both with the histograms they would have computed
(docs/recovery.md, "Colour in the offline pass").
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from pftrack.io.mot import write_mot
from pftrack.recovery import fill_gaps, link_tracklets
from pftrack.recovery.fill import side_frames
from pftrack.recovery.linking import (
    BoxColours,
    LinkConfig,
    frame_histograms,
    link_costs,
    link_frames,
    split_tracks,
)
from pftrack.synthetic import Scene, make_scene


class _Counted(Sequence[np.ndarray]):
    """Frames that record every index asked for."""

    def __init__(self, frames: Sequence[np.ndarray]) -> None:
        self.frames = frames
        self.asked: list[int] = []

    def __len__(self) -> int:
        return len(self.frames)

    def __getitem__(self, k):  # type: ignore[no-untyped-def]  # int only, as the readers ask
        self.asked.append(int(k))
        return self.frames[k]


def _behind_post() -> tuple[Scene, np.ndarray]:
    """make_scene's walkers (120 frames, seed 0) and their truth, the rows behind the lamp
    post dropped: holes inside the ids."""
    scene = make_scene(n_frames=120, rng=0)
    assert scene.occluder is not None
    x, _, w, _ = scene.occluder
    rows = scene.truth.copy()
    centre = rows[:, 2] + 0.5 * rows[:, 4]
    return scene, rows[(centre < x - 5) | (centre > x + w + 5)]


def _fragments() -> tuple[list[np.ndarray], np.ndarray]:
    """:func:`_behind_post`'s rows, each piece after a hole of 5 frames or more given a new id
    (a tracker's fragments for the linker); then a tenth of the rows dropped: short holes
    inside the ids (for the fill)."""
    scene, rows = _behind_post()
    rows = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    step = np.diff(rows[:, 0])
    same = rows[1:, 1] == rows[:-1, 1]
    new = np.r_[True, ~same | (step > 5)].cumsum()
    rows[:, 1] = new
    rows = rows[np.random.default_rng(0).random(len(rows)) > 0.1]
    rows = rows[np.lexsort((rows[:, 1], rows[:, 0]))]
    return list(scene.frames), rows


def _short_holes(rows: np.ndarray) -> int:
    r = rows[np.lexsort((rows[:, 0], rows[:, 1]))]
    step = np.diff(r[:, 0])
    return int(((r[1:, 1] == r[:-1, 1]) & (step > 1)).sum())


def test_one_pass_gives_the_two_passes_results() -> None:
    frames, rows = _fragments()
    cfg = LinkConfig()
    assert len(link_frames(rows, cfg)) > 0 and _short_holes(rows) > 0  # both readers read
    two = _Counted(frames)
    linked, mapping = link_tracklets(rows, cfg, two)
    filled, report = fill_gaps(linked, "linear", frames=two)
    assert mapping and report.n_gaps > len(mapping)  # the joins' holes and the ids' own
    assert any(b <= a for a, b in zip(two.asked, two.asked[1:], strict=False))  # two passes

    one = _Counted(frames)
    colours = BoxColours(one, rows, link_frames(rows, cfg) | side_frames(rows, cfg.max_gap))
    linked1, mapping1 = link_tracklets(rows, cfg, colours)
    filled1, report1 = fill_gaps(linked1, "linear", frames=colours)
    assert one.asked == sorted(set(one.asked))  # one pass, each frame once
    assert set(one.asked) >= set(two.asked)  # the union of both readers' frames
    assert mapping1 == mapping
    assert np.array_equal(filled1, filled)
    assert report1 == report


def test_the_linkers_costs_are_its_own() -> None:
    """The colour term of every pair is the one reading the frames gives, bit for bit."""
    frames, rows = _fragments()
    cfg = LinkConfig()
    tracks = split_tracks(rows)
    ids, i, j, cost = link_costs(tracks, cfg, frames)
    colours = BoxColours(frames, rows, link_frames(rows, cfg))
    ids1, i1, j1, cost1 = link_costs(tracks, cfg, colours)
    assert ids1 == ids and np.array_equal(i1, i) and np.array_equal(j1, j)
    assert np.array_equal(cost1, cost)
    _, _, _, motion_only = link_costs(tracks, cfg)
    assert not np.array_equal(motion_only, cost)  # the colour term is there


def test_histograms_match_the_frames_own() -> None:
    """Any boxes asked at a read frame equal frame_histograms on the frames; boxes or frames
    that were not read beforehand are read now (never a wrong or missing answer)."""
    frames, rows = _fragments()
    wanted = {9, 40, 77}
    counted = _Counted(frames)
    colours = BoxColours(counted, rows, wanted)
    assert counted.asked == [9, 40, 77]
    at = {f: rows[rows[:, 0] == f + 1, 2:6][::-1] for f in sorted(wanted)}  # reversed order
    at[50] = rows[rows[:, 0] == 51, 2:6]  # not read before
    at[40] = np.vstack([at[40], [[3.0, 4.0, 20.0, 30.0]]])  # a box no row has
    at[len(frames) + 3] = rows[:2, 2:6]  # past the frames' end
    at[12] = np.zeros((0, 4))
    got, want = colours.histograms(at), frame_histograms(at, frames)
    assert got.keys() == want.keys()
    for f in want:
        g, w = got[f], want[f]
        assert (g is None) == (w is None)
        if g is not None and w is not None:
            assert np.array_equal(g, w)
    assert len(colours) == len(frames) and colours[5] is frames[5]


def test_no_colour_reads_nothing() -> None:
    _, rows = _fragments()
    assert link_frames(rows, LinkConfig(w_appearance=0.0)) == set()
    assert link_frames(np.zeros((0, 10)), LinkConfig()) == set()
    assert side_frames(np.zeros((0, 10)), 30) == set()
    one = np.array([[1, 1, 0, 0, 5, 5], [4, 1, 0, 0, 5, 5], [40, 1, 0, 0, 5, 5]], float)
    assert side_frames(one, 30) == {0, 3}  # the 35-frame hole is longer than max_gap
    with pytest.raises(ValueError, match="side_frames"):
        side_frames(np.zeros((2, 3)), 30)
    with pytest.raises(ValueError, match="link_frames.*duplicate"):
        link_frames(np.array([one[0], one[0]]), LinkConfig())
    with pytest.raises(ValueError, match="link_frames.*id -1"):
        link_frames(np.array([[1, -1, 0, 0, 5, 5]], float), LinkConfig())


def test_recover_link_video_reads_in_one_pass(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The command's output is the two passes' (the library called as before) and its
    frames are asked for in increasing order, each once."""
    import cv2

    from pftrack.cli import main
    from pftrack.io import video as video_module
    from pftrack.io.mot import read_mot
    from pftrack.recovery.fill import copied_values

    frames, rows = _fragments()
    folder = tmp_path / "scene"
    folder.mkdir()
    for k, image in enumerate(frames, start=1):
        cv2.imwrite(str(folder / f"{k:06d}.png"), image)
    src = tmp_path / "frag.txt"
    write_mot(src, rows, exact=True)
    with video_module.FrameSequence(folder) as seq:
        cfg = LinkConfig()
        linked, _ = link_tracklets(read_mot(src), cfg, seq)
        want, _ = fill_gaps(linked, "linear", frames=seq)
    asked: list[int] = []
    real = video_module.FrameSequence.__getitem__

    def record(self: video_module.FrameSequence, index: int) -> np.ndarray:
        asked.append(int(index))
        return real(self, index)  # type: ignore[no-any-return]

    monkeypatch.setattr(video_module.FrameSequence, "__getitem__", record)
    out = tmp_path / "r.txt"
    argv = ["-q", "recover", str(src), "--out", str(out), "--link", "--method", "linear"]
    assert main([*argv, "--video", str(folder)]) == 0
    assert asked and asked == sorted(set(asked))
    two = tmp_path / "two.txt"  # written as the command writes
    write_mot(two, want, exact=copied_values(read_mot(src), want))
    assert out.read_bytes() == two.read_bytes()
