"""Linking, gap filling and the ``pftrack recover`` / ``experiment gaps`` commands."""

from __future__ import annotations

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot, write_mot
from pftrack.recovery.fill import fill_gaps
from pftrack.recovery.linking import FLAG_COLUMN, LinkConfig, link_cost_matrix, link_tracklets


def walker(tid, frames, x0, y0, vx, vy, w=20.0, h=50.0):
    f = np.asarray(frames, dtype=float)
    rows = np.zeros((len(f), 10))
    rows[:, 0] = f
    rows[:, 1] = tid
    rows[:, 2] = x0 + vx * f - w / 2
    rows[:, 3] = y0 + vy * f - h / 2
    rows[:, 4] = w
    rows[:, 5] = h
    rows[:, 6] = 1
    rows[:, 7:] = -1
    return rows


def scene():
    # object A fragmented into ids 1 and 5 (gap of 9 frames); object B (id 2) far away with a
    # hole of 4 frames; id 7 starts after id 2 ends but far from it (must not be linked)
    return np.vstack(
        [
            walker(1, range(1, 41), 100, 100, 2.0, 0.5),
            walker(5, range(50, 90), 100, 100, 2.0, 0.5),
            walker(2, list(range(1, 30)) + list(range(35, 60)), 400, 300, -1.0, 0.2),
            walker(7, range(62, 90), 50, 500, 1.0, 0.0),
        ]
    )


def test_link_tracklets_joins_fragments_of_one_object_only():
    rows, mapping = link_tracklets(scene(), LinkConfig(max_gap=20, max_distance=30))
    assert mapping == {5: 1}
    assert set(np.unique(rows[:, 1]).astype(int)) == {1, 2, 7}


def test_link_respects_the_gap_gate():
    _, mapping = link_tracklets(scene(), LinkConfig(max_gap=5, max_distance=30))
    assert mapping == {}


def _frames_with_colours(rows, colours, n_frames=100, size=(600, 700)):
    """BGR frames in which each id's box is painted in its colour (grey background)."""
    frames = [np.full((*size, 3), 128, np.uint8) for _ in range(n_frames)]
    for r in rows:
        f, tid = int(r[0]) - 1, int(r[1])
        x0, y0 = int(r[2]), int(r[3])
        frames[f][y0 : y0 + int(r[5]), x0 : x0 + int(r[4])] = colours[tid]
    return frames


def test_colour_term_uses_the_hsv_histograms():
    rows = scene()
    cfg = LinkConfig(max_gap=20, max_distance=30)
    ids, plain = link_cost_matrix(
        {t: rows[rows[:, 1] == t] for t in np.unique(rows[:, 1]).astype(int)}, cfg
    )
    i, j = ids.index(1), ids.index(5)
    same = _frames_with_colours(
        rows, {1: (0, 0, 255), 5: (0, 0, 255), 2: (255, 0, 0), 7: (0, 255, 0)}
    )
    other = _frames_with_colours(
        rows, {1: (0, 0, 255), 5: (255, 0, 0), 2: (255, 0, 0), 7: (0, 255, 0)}
    )
    per_id = {t: rows[rows[:, 1] == t] for t in ids}
    _, c_same = link_cost_matrix(per_id, cfg, same)
    _, c_other = link_cost_matrix(per_id, cfg, other)
    # same colour: Bhattacharyya distance 0, the cost is the motion cost alone
    assert c_same[i, j] == pytest.approx(plain[i, j], abs=1e-6)
    # red against blue: no common bin, distance 1
    assert c_other[i, j] == pytest.approx(plain[i, j] + cfg.w_appearance, abs=1e-6)
    assert link_tracklets(rows, cfg, same)[1] == {5: 1}


def test_frames_must_be_a_sequence_and_cover_the_rows():
    """A user trial: a generator failed on ``len``; three frames for rows of 24 frames left
    the colour term out of later ends without a word."""
    rows = scene()
    cfg = LinkConfig(max_gap=20, max_distance=30)
    frames = _frames_with_colours(
        rows, {1: (0, 0, 255), 5: (0, 0, 255), 2: (255, 0, 0), 7: (0, 255, 0)}
    )
    with pytest.raises(TypeError, match="frames must be a sequence indexable by frame - 1"):
        link_tracklets(rows, cfg, iter(frames))  # type: ignore[arg-type]
    last = int(rows[:, 0].max())
    with pytest.warns(UserWarning, match=f"frames holds 3 frames, the rows reach frame {last}"):
        link_tracklets(rows, cfg, frames[:3])


def test_fill_gaps_flags_rows_and_is_exact_on_straight_walkers():
    rows, _ = link_tracklets(scene(), LinkConfig(max_gap=20, max_distance=30))
    filled, rep = fill_gaps(rows, "gdt-bi", max_gap=20)
    assert rep.n_gaps == 2 and rep.n_filled_rows == 9 + 5
    new = filled[filled[:, FLAG_COLUMN] == 1]
    assert len(new) == 14
    truth = walker(1, new[new[:, 1] == 1, 0], 100, 100, 2.0, 0.5)
    np.testing.assert_allclose(new[new[:, 1] == 1, 2:6], truth[:, 2:6], atol=1e-6)
    keys = filled[:, 0] * 1000 + filled[:, 1]
    assert len(np.unique(keys)) == len(keys)
    # sorted by (frame, id)
    assert np.all(np.diff(keys) > 0)


def test_fill_rejects_duplicates():
    rows = scene()
    with pytest.raises(ValueError, match="duplicate rows for frame 1, id 1"):
        fill_gaps(np.vstack([rows, rows[:1]]))


def test_cli_recover_twice_changes_nothing(tmp_path, capsys):
    src = tmp_path / "tracks.txt"
    write_mot(src, scene())
    before = src.read_bytes()
    out1 = tmp_path / "filled.txt"
    out2 = tmp_path / "filled2.txt"
    assert (
        main(
            [
                "recover",
                str(src),
                "--out",
                str(out1),
                "--link",
                "--max-gap",
                "20",
                "--max-distance",
                "30",
            ]
        )
        == 0
    )
    assert src.read_bytes() == before  # input untouched
    assert (
        main(
            [
                "recover",
                str(out1),
                "--out",
                str(out2),
                "--link",
                "--max-gap",
                "20",
                "--max-distance",
                "30",
            ]
        )
        == 0
    )
    assert out1.read_bytes() == out2.read_bytes()
    rows = read_mot(out1)
    assert np.sum(rows[:, FLAG_COLUMN] == 1) == 14  # the flag round-trips through read_mot
    assert "interpolated flag: column 8" in capsys.readouterr().out


def test_cli_recover_refuses_to_overwrite_input(tmp_path, capsys):
    src = tmp_path / "tracks.txt"
    write_mot(src, scene())
    before = src.read_bytes()
    assert main(["recover", str(src), "--out", str(src)]) == 2
    assert "--in-place" in capsys.readouterr().err
    assert src.read_bytes() == before
    assert main(["recover", str(src), "--out", str(src), "--in-place"]) == 0
    assert src.read_bytes() != before


def test_cli_recover_reports_bad_rows_with_line_number(tmp_path, capsys):
    src = tmp_path / "bad.txt"
    src.write_text("1,1,10,10,5,5,1,-1,-1,-1\n# comment\n2,1,11,oops,5,5,1,-1,-1,-1\n")
    assert main(["recover", str(src), "--out", str(tmp_path / "o.txt")]) == 2
    assert "bad.txt:3" in capsys.readouterr().err
    src.write_text("1,1,10,10,5,5,1,-1,-1,-1\n\n1,1,11,10,5,5,1,-1,-1,-1\n")
    assert main(["recover", str(src), "--out", str(tmp_path / "o.txt")]) == 2
    assert "lines 1 and 3" in capsys.readouterr().err
    src.write_text("1,2,10,10,5,5,1,-1,-1,-1\n# comment\n1,19.5,11,10,5,5,1,-1,-1,-1\n")
    for command in ("recover", "smooth"):
        assert main([command, str(src), "--out", str(tmp_path / "o.txt")]) == 2
        err = capsys.readouterr().err  # was: "fill_gaps: track id 19.5 ..." without the line
        assert "bad.txt:3: track id 19.5 is not an integer" in err and "fill_gaps" not in err
    for big, shown in (("2147483648", "2147483648"), ("1e300", "1e+300")):
        src.write_text(f"1,{big},1,1,2,2\n")
        assert main(["recover", str(src), "--out", str(tmp_path / "o.txt")]) == 2
        err = capsys.readouterr().err  # was: "track id 2.14748e+09", not the value
        assert f"bad.txt:1: track id {shown} is not an integer with |id| <= 2147483647" in err
    assert not (tmp_path / "o.txt").exists()


def test_cli_a_huge_id_is_quoted_as_the_file_writes_it(tmp_path, capsys):
    """An id past 2**53 (a 64-bit id, as NVIDIA DeepStream's) is read as the nearest double:
    the refusal named 9007199254740992 for a file holding 9007199254740993, a number the user
    could not find in it. The line is quoted, as every other refused line is."""
    src = tmp_path / "big.txt"
    for big in ("9007199254740993", "18446744069414584321"):
        line = f"1,{big},10,10,5,5,1,-1,-1,-1"
        src.write_text(f"1,1,10,10,5,5,1,-1,-1,-1\n{line}\n")
        for command in ("recover", "smooth"):
            assert main([command, str(src), "--out", str(tmp_path / "o.txt")]) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and "big.txt:2: track id " in err, err
            assert err.endswith(f"{line!r}\n"), err
    assert not (tmp_path / "o.txt").exists()


def synthetic_gt():
    rows = []
    rng = np.random.default_rng(0)
    for tid in range(1, 7):
        f = np.arange(1, 150)
        y0 = 40 + 30 * tid
        x = 10 + 2.0 * f
        y = y0 + 5 * np.sin(f / 15.0 + tid) + np.cumsum(rng.normal(0, 0.05, len(f)))
        for fr, xx, yy in zip(f, x, y, strict=True):
            rows.append([fr, tid, xx - 10, yy - 20, 20, 40, 1, -1, -1, -1])
    rows.append([1, 99, 150, 120, 20, 40, 1, -1, -1, -1])  # starts (and ends) inside the mask
    rows.append([2, 99, 151, 120, 20, 40, 1, -1, -1, -1])
    return np.array(rows)


def test_experiment_gaps_protocol():
    from pftrack.recovery import experiment as E

    trajs = E.trajectories(synthetic_gt())
    gaps, n_traj = E.find_gaps(trajs, (140, 60, 100, 100))
    # trajectories 1-3 cross the mask (y centre 70..130 within 60..160), id 99 is left out
    assert n_traj == len({g.track_id for g in gaps}) and 99 not in {g.track_id for g in gaps}
    for g in gaps:
        assert g.segment_a[-1, 0] + 1 == g.truth[0, 0]
        assert g.truth[-1, 0] + 1 == g.segment_b[0, 0]
        x, y = g.truth[:, 1], g.truth[:, 2]
        assert np.all((x >= 140) & (x < 240) & (y >= 60) & (y < 160))
    # the vectorised grid count agrees with find_gaps
    xs, ys, nt, ng = E.count_gaps_grid(trajs, 100, 400, 300, 20)
    for iy in range(0, len(ys), 3):
        for ix in range(0, len(xs), 3):
            g2, n2 = E.find_gaps(trajs, (xs[ix], ys[iy], 100, 100))
            assert (nt[iy, ix], ng[iy, ix]) == (n2, len(g2))


def test_cli_experiment_gaps(tmp_path, capsys):
    gt = tmp_path / "gt.txt"
    write_mot(gt, synthetic_gt())
    fig = tmp_path / "fig.png"
    assert (
        main(
            [
                "experiment",
                "gaps",
                "--gt",
                str(gt),
                "--grid",
                "40",
                "--repeat",
                "1",
                "--max-positions",
                "3",
                "--figure",
                str(fig),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    for word in ("MMAE x", "MMAE total", "MAE total", "time (ms)", "median over", "gdt-bi"):
        assert word in out
    import cv2

    img = cv2.imread(str(fig))
    assert img is not None and img.ndim == 3
    assert main(["experiment", "gaps", "--gt", str(gt), "--mask", "1,2,3"]) == 2


@pytest.mark.parametrize(
    ("width", "height", "scale"),
    [(480, 360, 1.0), (640, 480, 1.0), (1280, 960, 2.0), (1920, 1440, 3.0), (0, 0, 1.0)],
)
def test_pixel_scale_grows_with_the_diagonal_above_640x480(width, height, scale):
    from pftrack.recovery.linking import pixel_scale

    assert pixel_scale(width, height) == pytest.approx(scale)


def jumped(factor):
    """One walker in two fragments, 40 px (times `factor`) off its motion after the gap.

    The boxes reach 640x480 times `factor`: a corner box marks the frame's extent.
    """
    a = walker(1, range(1, 21), 100, 150, 2.0, 0.0)
    b = walker(2, range(31, 51), 140, 150, 2.0, 0.0)
    corner = walker(3, [1], 620, 455, 0.0, 0.0, w=40, h=50)
    rows = np.vstack([a, b, corner])
    rows[:, 2:6] *= factor
    return rows


def test_the_gate_grows_with_the_boxes_extent():
    from pftrack.recovery.linking import gate_for_rows

    cfg = LinkConfig()
    assert gate_for_rows(cfg, jumped(1.0)) == cfg
    assert gate_for_rows(cfg, jumped(2.0)).max_distance == pytest.approx(100.0)
    assert gate_for_rows(cfg, np.zeros((0, 10))) == cfg
    # the same footage at twice the size links as at its own size
    for factor in (1.0, 2.0):
        _, mapping = link_tracklets(jumped(factor), gate_for_rows(cfg, jumped(factor)))
        assert mapping == {2: 1}
    _, mapping = link_tracklets(jumped(2.0), cfg)  # 80 px against a 50 px gate
    assert mapping == {}


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_cli_gate_follows_the_frame(command, tmp_path, capsys):
    src = tmp_path / "big.txt"
    write_mot(src, jumped(2.0))
    link = ["--link"] if command == "recover" else []
    assert main([command, str(src), "--out", str(tmp_path / "a.txt"), *link]) == 0
    assert set(read_mot(tmp_path / "a.txt")[:, 1].astype(int)) == {1, 3}
    # a gate given in pixels is taken as it is (smooth had no --max-distance)
    out = tmp_path / "b.txt"
    assert main([command, str(src), "--out", str(out), *link, "--max-distance", "50"]) == 0
    assert set(read_mot(out)[:, 1].astype(int)) == {1, 2, 3}


def test_a_stray_row_does_not_widen_the_gate():
    # was: one box at x = 2500 in a 768x576 file made the gate 3.6 times wider, and fragments
    # of different people were joined
    from pftrack.recovery.linking import gate_for_rows

    cfg = LinkConfig()
    rows = jumped(2.0)
    rows = np.vstack([rows] * 60)  # enough rows for a 1 % tail
    rows[:, 0] = np.arange(1, len(rows) + 1)
    want = gate_for_rows(cfg, rows)
    stray = np.vstack([rows, [[len(rows) + 1, 999, 2500, 1500, 40, 80, 1, -1, -1, -1]]])
    said = r"^1 row\(s\) reach far past the others \(the first: frame 2461, id 999, right "
    with pytest.warns(UserWarning, match=said):
        assert gate_for_rows(cfg, stray) == want


def _smoothed_bytes(rows: np.ndarray, path) -> bytes:  # type: ignore[no-untyped-def]
    from pftrack.tracking.offline import smoothed_copies

    write_mot(path, rows, exact=smoothed_copies(rows))  # as pftrack smooth writes
    return path.read_bytes()


def test_smooth_tracks_is_pftrack_smooth_on_large_frames(tmp_path, capsys):
    """Regression (user trial): ``smooth_tracks(rows)`` kept the 50 px gate where ``pftrack
    smooth`` grows it with the frame (a split ADL-Rundle-6, 1920x1080: 32 ids from the command,
    34 from the function). Its default, ``link="auto"``, is now the command's gate; a
    LinkConfig is used as given (the tracker passes its own)."""
    from pftrack.tracking import smooth_tracks

    rows = jumped(3.0)  # 1920x1440: a gate of 150 px; the walker is 120 px off its motion
    src = tmp_path / "big.txt"
    write_mot(src, rows)
    for args, kwargs in (([], {}), (["--max-gap", "5"], {"max_gap": 5})):
        cli = tmp_path / "cli.txt"
        assert main(["-q", "smooth", str(src), "--out", str(cli), *args]) == 0
        got = smooth_tracks(read_mot(src), **kwargs)
        assert _smoothed_bytes(got, tmp_path / "fn.txt") == cli.read_bytes(), args
    assert set(smooth_tracks(rows)[:, 1].astype(int)) == {1, 3}  # joined, as the command
    assert set(smooth_tracks(rows, max_gap=5)[:, 1].astype(int)) == {1, 2, 3}  # a 10-frame gap
    assert set(smooth_tracks(rows, link=LinkConfig())[:, 1].astype(int)) == {1, 2, 3}  # 50 px
    with pytest.raises(TypeError, match="smooth_tracks: link must be a LinkConfig, 'auto' or "):
        smooth_tracks(rows, link="big")  # type: ignore[arg-type]


@pytest.mark.dataset
def test_smooth_tracks_is_pftrack_smooth_on_adl_rundle_6(tmp_path, capsys):
    """The trial's case: ADL-Rundle-6's ground truth (1920x1080) split at every 40th frame."""
    from pftrack.tracking import smooth_tracks

    from ..conftest import dataset

    gt = read_mot(dataset("mot15-gt") / "ADL-Rundle-6" / "gt.txt")
    gt = gt[(gt[:, 0] % 40 != 0) & (gt[:, 0] % 40 != 1)]  # holes of 2 frames
    gt[:, 1] = gt[:, 1] * 100 + gt[:, 0] // 40  # a new id after each hole
    gt[:, 6:] = (1, -1, -1, -1)
    src = tmp_path / "split.txt"
    write_mot(src, gt)
    cli = tmp_path / "cli.txt"
    assert main(["-q", "smooth", str(src), "--out", str(cli)]) == 0
    got = smooth_tracks(read_mot(src))
    assert _smoothed_bytes(got, tmp_path / "fn.txt") == cli.read_bytes()


def test_smooth_refuses_a_gate_without_linking(tmp_path, capsys):
    src = tmp_path / "t.txt"
    write_mot(src, jumped(1.0))
    argv = ["smooth", str(src), "--out", str(tmp_path / "o.txt"), "--no-link"]
    assert main([*argv, "--max-distance", "5"]) == 2
    assert capsys.readouterr().err.strip() == (
        "pftrack smooth: error: --max-distance is the linking gate: drop it or --no-link"
    )


class _ForwardOnly:
    """Frames that may be asked for only in increasing order, each once (as a video is read)."""

    def __init__(self, frames):
        self.frames, self.asked = frames, []

    def __len__(self):
        return len(self.frames)

    def __getitem__(self, i):
        assert not self.asked or i > self.asked[-1], f"frame {i} asked after {self.asked}"
        self.asked.append(i)
        return self.frames[i]


def test_colour_term_reads_the_frames_of_fragment_ends_once_in_order():
    """Was: frames asked for in the order of the pairs, so a video had to be held whole."""
    rows = np.vstack(  # object A: ids 1 then 3; object B, far away: ids 2 then 4
        [
            walker(1, range(1, 61), 100, 100, 2.0, 0.5),
            walker(3, range(65, 91), 100, 100, 2.0, 0.5),
            walker(2, range(1, 21), 500, 400, -1.0, 0.2),
            walker(4, range(25, 51), 500, 400, -1.0, 0.2),
        ]
    )
    cfg = LinkConfig(max_gap=20, max_distance=30)
    colours = {1: (0, 0, 255), 3: (0, 0, 255), 2: (255, 0, 0), 4: (0, 255, 0)}
    frames = _frames_with_colours(rows, colours)
    per_id = {t: rows[rows[:, 1] == t] for t in np.unique(rows[:, 1]).astype(int)}
    forward = _ForwardOnly(frames)
    ids, cost = link_cost_matrix(per_id, cfg, forward)
    assert forward.asked == [19, 24, 59, 64]  # the ends of the two gated pairs (was 59 first)
    assert np.array_equal(cost, link_cost_matrix(per_id, cfg, frames)[1])
    assert np.isfinite(cost).sum() == 2


def _scene_video(path, n_frames=100, size=(600, 700)):
    from pftrack.io.video_writer import VideoWriter

    rows = scene()
    colours = {1: (0, 0, 255), 5: (0, 0, 255), 2: (255, 0, 0), 7: (0, 255, 0)}
    with VideoWriter(path, 10.0) as writer:
        for frame in _frames_with_colours(rows, colours, n_frames=max(n_frames, 90))[:n_frames]:
            writer.write(np.ascontiguousarray(frame[: size[0], : size[1]]))
    return path


def test_cli_recover_reads_the_video_lazily(tmp_path, capsys, monkeypatch):
    """Was: every frame of --video in memory (2.5 GB for 400 frames of 1080p)."""
    import pftrack.io.video as video

    def refuse(*args, **kwargs):
        raise AssertionError("the whole video was read into memory")

    monkeypatch.setattr(video, "read_frames", refuse)
    tracks = tmp_path / "t.txt"
    write_mot(tracks, scene())
    v = _scene_video(tmp_path / "v.avi")
    out = tmp_path / "o.txt"
    argv = ["recover", str(tracks), "--link", "--video", str(v), "--out", str(out)]
    assert main([*argv, "--method", "linear"]) == 0
    assert "1 fragment linked" in capsys.readouterr().out  # was: "1 fragments linked"
    assert set(np.unique(read_mot(out)[:, 1]).astype(int)) == {1, 2, 7}


@pytest.mark.parametrize(
    ("n_frames", "size", "message"),
    [
        (50, (600, 700), r"has 50 frames but .*t\.txt has rows up to frame 89: not the video"),
        (100, (150, 200), r"is 200x150 px but .*t\.txt has a box with left \d+ \(frame \d+, "
                          r"id \d+\), past its right edge"),
    ],
)  # fmt: skip
def test_cli_recover_refuses_a_video_that_is_not_the_tracks_own(
    tmp_path, capsys, n_frames, size, message
):
    """Was: accepted, the colour term silently dropped where frames were missing."""
    import re

    tracks = tmp_path / "t.txt"
    write_mot(tracks, scene())
    v = _scene_video(tmp_path / "v.avi", n_frames, size)
    out = tmp_path / "o.txt"
    assert main(["recover", str(tracks), "--link", "--video", str(v), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(message, err), err
    assert not out.exists()


def test_cli_recover_counts_a_video_whose_header_says_too_few_frames(tmp_path, capsys):
    """An AVI whose header says 50 of its 100 frames: was refused as not the tracks' video."""
    import warnings

    from tests.io.test_video import _header_count

    tracks = tmp_path / "t.txt"
    write_mot(tracks, scene())
    v = _header_count(_scene_video(tmp_path / "v.avi", 100, (600, 700)), 50)
    out = tmp_path / "o.txt"
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # as outside the test suite (which makes them errors)
        assert main(["recover", str(tracks), "--link", "--video", str(v), "--out", str(out)]) == 0
    assert "its header says 50 frames but it holds 100 (counted)" in capsys.readouterr().err
    assert out.exists()


@pytest.mark.parametrize("tail", [",0.9,1", ",0.9,1,-1"])
def test_padded_columns_that_look_filled_are_said(tail, tmp_path, capsys):
    # was: an 8- or 9-column file with a class 1 in column 8 read as rows pftrack filled, and
    # the output's filled rows could not be told from them, without a word
    import warnings

    src = tmp_path / "c.txt"
    src.write_text(f"1,1,10,10,20,40{tail}\n5,1,30,10,20,40{tail}\n")
    full = tmp_path / "f.txt"  # ten columns: the mark is the file's own, nothing to say
    full.write_text("1,1,10,10,20,40,0.9,1,-1,-1\n5,1,30,10,20,40,0.9,1,-1,-1\n")
    fields = tail.count(",") + 6
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # as outside the test suite (which makes them errors)
        assert main(["recover", str(src), "--out", str(tmp_path / "o.txt")]) == 0
        err = capsys.readouterr().err
        assert main(["recover", str(full), "--out", str(tmp_path / "o2.txt")]) == 0
        assert "warning" not in capsys.readouterr().err
    assert (
        f"pftrack recover: warning: {src}: 2 row(s) have 1 in column 8 and {fields} columns "
        "(the missing ones padded with -1)" in err
    )


def test_boxes_four_times_apart_in_area_are_not_linked(tmp_path, capsys):
    """A user trial: two one-row fragments of ByteTrack's false positives on TUD-Campus, 4.1
    times apart in area, were joined across 30 frames and 30 boxes filled between them."""
    rows = np.array([
        [7, 8, 66.5255, 212.778, 30.7028, 46.31, 0.685141, -1, -1, -1],
        [38, 16, 34.3067, 166.579, 68.0333, 86.014, 0.588207, -1, -1, -1],
    ])  # fmt: skip
    assert link_tracklets(rows, LinkConfig())[1] == {}
    assert link_tracklets(rows, LinkConfig(max_area_ratio=None))[1] == {16: 8}
    twice = rows.copy()
    twice[1, 4:6] = twice[0, 4:6] * 1.9  # 3.6 times the area: within the gate
    assert link_tracklets(twice, LinkConfig())[1] == {16: 8}
    src = tmp_path / "two.txt"
    write_mot(src, rows)
    assert main(["-q", "smooth", str(src), "--out", str(tmp_path / "s.txt")]) == 0
    assert len(read_mot(tmp_path / "s.txt")) == 2
    for bad in (0.5, float("nan"), True, "4"):
        with pytest.raises(ValueError, match="LinkConfig.max_area_ratio is"):
            LinkConfig(max_area_ratio=bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("zero", [(4,), (5,), (4, 5)])
def test_a_box_without_area_does_not_slip_past_the_area_gate(zero, tmp_path):
    """Was: a box of width or height 0 was not compared (a ratio with a 0 in it), so the
    fragment it ends was joined to one of any size: 0 x 46 px to 68 x 86 px, 30 frames filled.
    A box without area is as far in area from any box with one as the gate can tell."""
    rows = np.array([
        [7, 8, 66.5255, 212.778, 30.7028, 46.31, 0.685141, -1, -1, -1],
        [38, 16, 34.3067, 166.579, 68.0333, 86.014, 0.588207, -1, -1, -1],
    ])  # fmt: skip

    def flat(which: list[int]) -> np.ndarray:
        """`rows` with the boxes of rows `which` made 0 wide or tall about their centres."""
        out = rows.copy()
        for c in zero:
            out[which, c - 2] += out[which, c] / 2  # the centre stays: the motion gate too
            out[which, c] = 0.0
        return out

    for k in (0, 1):  # the end or the start of the join
        assert link_tracklets(flat([k]), LinkConfig())[1] == {}
        assert link_tracklets(flat([k]), LinkConfig(max_area_ratio=None))[1] == {16: 8}
    # two boxes without area: neither is larger than the other
    assert link_tracklets(flat([0, 1]), LinkConfig())[1] == {16: 8}
    src = tmp_path / "flat.txt"
    write_mot(src, flat([0]))
    assert main(["-q", "smooth", str(src), "--out", str(tmp_path / "s.txt")]) == 0
    assert len(read_mot(tmp_path / "s.txt")) == 2  # nothing filled between them
