"""``pftrack recover`` / ``smooth`` outputs: observed rows kept, filled rows told apart.

Regression tests: column 8 holds the interpolated flag, and observed values there (MOT15 world
``x``, MOT16+ class) were rounded to 2 decimals, so ``0.99502`` became ``1.00`` and counted as
filled; re-running ``recover`` on its own output rewrote ``88.00`` as ``88``.
``smooth --no-link`` left the holes inside each id.
Batch ``recover --explain`` left out the box sizes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pftrack.cli import main
from pftrack.io.mot import read_mot
from pftrack.recovery.linking import FILLED_MARK, filled_mask
from pftrack.tracking import smooth_tracks
from tests.recovery.test_dataset import data_dir


def _walks(seed: int, n_ids: int = 6, n_frames: int = 100) -> list[np.ndarray]:
    """Random-walk box centres (frame, x, y) per id, frames 1..n_frames."""
    rng = np.random.default_rng(seed)
    t = np.arange(1, n_frames + 1, dtype=np.float64)
    return [
        np.column_stack([t, 200 + np.cumsum(rng.uniform(-2, 2, (n_frames, 2)), axis=0)])
        for _ in range(n_ids)
    ]


def _num(v: float, decimals: int) -> str:
    """`v` rounded to `decimals`, in its shortest form (``176.22``, ``40``)."""
    return np.format_float_positional(round(float(v), decimals), trim="-")


def _lines(kind: str, seed: int = 0) -> list[str]:
    """Text rows as a tracker (10 columns) or ground truth (MOT15 world, MOT16+ 9 columns)
    writes them, with a hole of frames 40-47 in every id; column 8 holds values near 1."""
    rng = np.random.default_rng(seed + 100)
    out = []
    for tid, c in enumerate(_walks(seed), start=1):
        for f, x, y in c:
            if 40 <= f <= 47:
                continue
            box = f"{int(f)},{tid},{_num(x - 10, 3)},{_num(y - 20, 2)},20.5,40"
            if kind == "tracker":  # conf with 6 decimals, no world coordinates
                out.append(f"{box},{_num(rng.uniform(0.5, 1), 6)},-1,-1,-1")
            elif kind == "mot15":  # world x near 1 (rounded to 2 decimals: 1.00), z = 0
                wx = rng.choice([0.99502, 1.004, -0.099279, 1])
                out.append(f"{box},1,{_num(wx, 6)},-9.6042,0")
            else:  # MOT16+: consider flag, class 1 (pedestrian), visibility
                out.append(f"{box},1,1,{_num(rng.uniform(0, 1), 5)}")
    return out


def _write(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(lines) + "\n")
    return path


def _by_key(rows: np.ndarray) -> np.ndarray:
    return rows[np.lexsort((rows[:, 1], rows[:, 0]))]


@pytest.mark.parametrize("kind", ["tracker", "mot15", "mot16"])
def test_recover_keeps_observed_rows_and_is_a_fixed_point(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    lines = _lines(kind)
    src = _write(tmp_path / "in.txt", lines)
    out, again = tmp_path / "out.txt", tmp_path / "again.txt"
    assert main(["recover", str(src), "--out", str(out)]) == 0
    assert "gaps filled with 48 rows" in capsys.readouterr().out  # 6 ids x 8 frames
    rows, given = read_mot(out), read_mot(src)
    filled = filled_mask(rows)
    assert filled.sum() == 48 and len(rows) == len(given) + 48
    np.testing.assert_array_equal(rows[~filled], _by_key(given))  # exact values, all columns
    np.testing.assert_array_equal(rows[filled, 7:], np.tile(FILLED_MARK, (48, 1)))
    assert np.all(np.isin(rows[filled, 0], np.arange(40, 48)))
    # the text of every observed row as given (9-column rows get z = -1)
    text = set(out.read_text().splitlines())
    assert {line + (",-1" if kind == "mot16" else "") for line in lines} <= text
    # running it on its own output changes nothing: no gap left, the same bytes
    assert main(["recover", str(out), "--out", str(again)]) == 0
    assert "48 input rows had it already" in capsys.readouterr().out
    assert again.read_bytes() == out.read_bytes()


def test_recover_output_in_shortest_form_is_rewritten_byte_for_byte(tmp_path: Path) -> None:
    """``88.00`` and ``-7.00`` come out as ``88`` and ``-7`` the first time, not the second."""
    lines = _lines("tracker")
    lines = [line.replace(",40,", ",40.00,") for line in lines]  # 2-decimal writers
    src = _write(tmp_path / "in.txt", lines)
    one, two = tmp_path / "one.txt", tmp_path / "two.txt"
    assert main(["recover", str(src), "--out", str(one)]) == 0
    assert ",40.00," not in one.read_text() and ",40," in one.read_text()
    assert main(["recover", str(one), "--out", str(two)]) == 0
    assert one.read_bytes() == two.read_bytes()


@pytest.mark.parametrize("kind", ["tracker", "mot15", "mot16"])
def test_smooth_flags_only_the_rows_it_adds(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str
) -> None:
    src = _write(tmp_path / "in.txt", _lines(kind))
    out = tmp_path / "out.txt"
    assert main(["smooth", str(src), "--out", str(out)]) == 0
    capsys.readouterr()
    rows, given = read_mot(out), _by_key(read_mot(src))
    filled = filled_mask(rows)
    assert filled.sum() == len(rows) - len(given) == 48
    # observed rows keep conf and columns 8-10 exactly (the boxes are the smoother's)
    np.testing.assert_array_equal(rows[~filled, 6:], given[:, 6:])


def test_smooth_no_link_fills_holes_inside_each_id_and_joins_none(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lines = _lines("tracker")
    # id 7 continues id 1 after frame 100: smooth joins them, --no-link must not
    c = _walks(0)[0]
    x, y = c[-1, 1:]
    lines += [f"{f},7,{x - 10 + 0.3 * (f - 100):.2f},{y - 20:.2f},20.5,40,1,-1,-1,-1"
              for f in range(103, 140)]  # fmt: skip
    src = _write(tmp_path / "in.txt", lines)
    linked, plain = tmp_path / "linked.txt", tmp_path / "plain.txt"
    assert main(["smooth", str(src), "--out", str(linked)]) == 0
    assert main(["smooth", str(src), "--out", str(plain), "--no-link"]) == 0
    capsys.readouterr()
    a, b, given = read_mot(linked), read_mot(plain), read_mot(src)
    assert set(a[:, 1]) == set(range(1, 7)) and set(b[:, 1]) == set(range(1, 8))
    assert filled_mask(a).sum() == 48 + 2 and filled_mask(b).sum() == 48  # + frames 101-102
    for tid in range(1, 8):  # every id of --no-link's output runs without a hole
        fr = np.sort(b[b[:, 1] == tid, 0])
        assert np.all(np.diff(fr) == 1), tid
    assert len(b) == len(given) + 48
    # a hole longer than --max-gap stays a hole, as with linking
    assert main(["smooth", str(src), "--out", str(plain), "--no-link", "--max-gap", "7"]) == 0
    assert filled_mask(read_mot(plain)).sum() == 0


def test_smooth_tracks_max_gap_fills_without_linking() -> None:
    rows = read_mot_text(_lines("tracker"))
    assert len(smooth_tracks(rows, link=None)) == len(rows)  # the library default: as before
    out = smooth_tracks(rows, link=None, max_gap=8)
    assert filled_mask(out).sum() == 48 and set(out[:, 1]) == set(rows[:, 1])
    assert len(smooth_tracks(rows, link=None, max_gap=7)) == len(rows)
    for bad in (0, 100_001):
        with pytest.raises(ValueError, match="smooth_tracks: max_gap is"):
            smooth_tracks(rows, link=None, max_gap=bad)
    for bad in (True, 2.5):
        with pytest.raises(TypeError, match="smooth_tracks: max_gap must be an integer"):
            smooth_tracks(rows, link=None, max_gap=bad)  # type: ignore[arg-type]


def read_mot_text(lines: list[str]) -> np.ndarray:
    return np.array([line.split(",") for line in lines], dtype=np.float64)


def test_batch_explain_prints_what_one_file_prints(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "tracks"
    folder.mkdir()
    for k, name in enumerate(("a", "b")):
        _write(folder / f"{name}.txt", _lines("tracker", seed=k))
    assert main(["recover", str(folder), "--out", str(tmp_path / "o"), "--workers", "0",
                 "--explain"]) == 0  # fmt: skip
    batch = capsys.readouterr().out
    for name in ("a", "b"):
        assert main(["recover", str(folder / f"{name}.txt"), "--out",
                     str(tmp_path / f"{name}.txt"), "--explain"]) == 0  # fmt: skip
        single = capsys.readouterr().out.split("\n", 1)[1]  # after the summary line
        assert "box centres (x, y):" in single and "box sizes (w, h):" in single
        assert f"{name}:\n{single}" in batch
    assert batch.count("box sizes (w, h):") == 2
    # a named method: nothing chosen, as for one file
    assert main(["recover", str(folder), "--out", str(tmp_path / "l"), "--workers", "0",
                 "--method", "linear", "--explain"]) == 0  # fmt: skip
    assert capsys.readouterr().out.count("filled by the method given, nothing was chosen") == 2


@pytest.mark.dataset
def test_pets_smooth_and_recover_flag_exactly_the_filled_rows(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The report: frames 100-115 cut from PETS09-S2L1; rows 125/13 and 721/6 (world x
    0.99502, 1.0049) were written ``1.00`` and counted as filled."""
    gt = data_dir() / "pets09-s2l1" / "gt.txt"
    if not gt.is_file():
        pytest.skip(f"dataset not available: {gt}")
    lines = [s for s in gt.read_text().splitlines() if not 100 <= int(s.split(",")[0]) <= 115]
    src = _write(tmp_path / "gap.txt", lines)
    for command in ("recover", "smooth"):
        out = tmp_path / f"{command}.txt"
        assert main([command, str(src), "--out", str(out)]) == 0
        rows = read_mot(out)
        assert filled_mask(rows).sum() == np.sum(rows[:, 7] == 1) == 96, command
    capsys.readouterr()
    assert set(lines) <= set((tmp_path / "recover.txt").read_text().splitlines())


@pytest.mark.parametrize("command", ["recover", "smooth"])
def test_observed_values_with_many_digits_are_kept_exactly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    """Regression: ``np.savetxt``'s values (``%.18e``) came out rounded to 2 decimals:
    x 499.1234567891234 as 499.12, conf 0.123456789012 as 0.12."""
    rows = read_mot(_write(tmp_path / "lines.txt", _lines("tracker")))
    rows[:, 2] += 0.1234567891234
    rows[:, 6] = 0.123456789012
    rows[::3, 9] = np.pi  # a world z of 16 digits
    src, out = tmp_path / "savetxt.txt", tmp_path / "out.txt"
    np.savetxt(src, rows, delimiter=",")
    argv = [command, str(src), "--out", str(out)]
    assert main(argv + (["--method", "linear"] if command == "recover" else [])) == 0
    capsys.readouterr()
    got, given = read_mot(out), _by_key(rows)
    filled = filled_mask(got)
    assert filled.sum() == 48
    if command == "recover":  # observed rows: every value as read
        np.testing.assert_array_equal(got[~filled], given)
        assert "4567891234," in out.read_text() and ",0.123456789012," in out.read_text()
    else:  # smoothed boxes are computed (2 decimals); conf and columns 8-10 are the rows'
        np.testing.assert_array_equal(got[~filled, 6:], given[:, 6:])
        assert np.all(np.round(got[:, 2:6], 2) == got[:, 2:6])
    assert np.all(got[filled, 6] == 0.123456789012)  # a filled row's conf: its neighbour's
    assert np.all(np.round(got[filled, 2:6], 2) == got[filled, 2:6])  # computed: 2 decimals
