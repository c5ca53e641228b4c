"""read_mot/write_mot: the vectorised paths give exactly what the line-by-line ones give."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from pftrack.io import mot


def _slow_read(path: Path) -> np.ndarray:
    rows = []
    for _, text in mot._data_lines(path):
        v = [float(f) for f in text.replace(",", " ").split()[:10]]
        rows.append(v + list(mot._DEFAULTS[len(v) :]))
    return np.asarray(rows, dtype=np.float64).reshape(-1, 10)


def test_write_equals_format_mot_row(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    n = 3000
    a = np.column_stack(
        [rng.integers(1, 100, n), rng.integers(-3, 9, n), rng.normal(0, 50, (n, 8))]
    )
    digits = rng.integers(0, 4, (n, 8))
    a[:, 2:] = np.round(a[:, 2:] * 10.0**digits) / 10.0**digits
    a[:, 4:6] = np.abs(a[:, 4:6])  # sizes as read_mot reads them (write_mot refuses others)
    a[::7, 2] = -0.0
    a[::11, 7] = 1e16
    a[::13, 4] = 3.999
    a[::17, 3] = -2.004
    mot.write_mot(tmp_path / "t.txt", a)
    o = a[np.lexsort((a[:, 1], a[:, 0]))]
    want = "".join(mot.format_mot_row(r) + "\n" for r in o)
    assert (tmp_path / "t.txt").read_text() == want


def test_fast_read_equals_line_by_line(tmp_path: Path) -> None:
    p = tmp_path / "t.txt"
    p.write_text("1,2,3.5,4,5,6,0.9,-1,-1,-1\n\n2,3,4,5,6,7,1,-1,-1,-1\n")
    np.testing.assert_array_equal(mot.read_mot(p), _slow_read(p))
    p.write_text("1 2 3 4 5 6\n2 3 4 5 6 7\n")  # whitespace, 6 columns
    got = mot.read_mot(p)
    np.testing.assert_array_equal(got, _slow_read(p))
    assert got[0, 6:].tolist() == [1.0, -1.0, -1.0, -1.0]
    p.write_text("# a comment\n1,2,3,4,5,6\n")  # comments: the line-by-line reader
    assert mot.read_mot(p).shape == (1, 10)
    p.write_text("")
    assert mot.read_mot(p).shape == (0, 10)
    p.write_text("# a comment\n")
    assert mot.read_mot(p).shape == (0, 10)
    p.write_text("# a comment\n1,2,3,4,0,0\n")  # zero sizes are read, as the fast path reads them
    assert mot.read_mot(p)[0, 4:6].tolist() == [0.0, 0.0]


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("1,2,3,4,5,6\n2,3,4,5,6\n", ":2: .*5 fields"),
        ("1.5,2,3,4,5,6\n", ":1: frame is 1.5"),
        ("1,2,3,4,-5,6\n", ":1: negative box"),
        ("1,2,nan,4,5,6\n", ":1: .*non-finite"),
        ("1,2,3,4,5,6\n1e10,2,3,4,5,6\n", r":2: frame is 1e10, expected an integer in 1\.\."),
        ("1,2,1e300,4,5,6\n", r":1: a box value is beyond ±1e\+09 px"),  # was: read, then
        ("1,2,3,4,5,-1e300\n", ":1: negative box"),  # "x2 <= x1" (1e300 + 8 == 1e300)
        ("1,2,3,4,5,2e9\n", r":1: a box value is beyond ±1e\+09 px"),
        # the line-by-line reader checks boxes after its loop: still the first bad line
        ("# c\n1,2,3,4,-5,6\n2,x,3,4,5,6\n", r":2: negative box width or height: '1,2,3,4,-5,6'"),
        ("# c\n1,2,3,4,5,6\n2,x,3,4,5,6\n3,2,3,4,-5,6\n", ":3: MOT file line has a non-number"),
        ("# c\n1,2,3,4,5,6\n2,2,3,4,5,-0.5\n", ":3: negative box"),
        ("# c\n1,2,3,4,5,6\n2,2,-2e9,4,-5,6\n", ":3: negative box"),  # size before far
        ("# c\n1,2,3,4,5,6\n2,2,-2e9,4,5,6\n", r":3: a box value is beyond ±1e\+09 px: '2,2,"),
        # a user trial: float() read 1_0 as 10, other scripts' digits, and 400 digits as "NaN or
        # inf"
        ("1,2,3,4,5,6\n1_0,2,3,4,5,6\n", r":2: MOT file line has a non-number: '1_0,"),
        ("1,2,1e9,4,20,6\n", r":1: a box's right or bottom edge is beyond ±1e\+09 px"),
        ("1,2,1e308,4,1e308,6\n", r":1: a box value is beyond ±1e\+09 px"),  # no overflow
        ("1,2,3,4,5,6\n\uff11,2,3,4,5,6\n", ":2: MOT file line has a non-number"),
        (
            "1,2,3,4,5,6\n2,2,3,4,5,6,1" + "0" * 400 + "\n",
            r":2: .*\(beyond a float's range\) in column 7",
        ),
    ],
)
def test_bad_lines_still_named(tmp_path: Path, text: str, match: str) -> None:
    p = tmp_path / "t.txt"
    p.write_text(text)
    with pytest.raises(ValueError, match=match):
        mot.read_mot(p)


def test_a_device_or_pipe_is_not_a_regular_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: 'detection file not found: /dev/null' (it exists: it is no regular file)."""
    import os

    from pftrack.cli import main

    os.mkfifo(tmp_path / "fifo")
    for path in (os.devnull, tmp_path / "fifo"):
        with pytest.raises(ValueError, match=r"detection file .* is not a regular file \(a"):
            mot.read_mot(path, what="detection file")
    with pytest.raises(ValueError, match=r"tracks file .* is a folder, not a file"):
        mot.read_mot(tmp_path, what="tracks file")
    with pytest.raises(FileNotFoundError, match=r"tracks file not found: "):
        mot.read_mot(tmp_path / "nosuch.txt", what="tracks file")
    out = ["--out", str(tmp_path / "o.txt")]
    for argv, message in (
        (["recover", os.devnull, *out], f"tracks file {os.devnull} is not a regular file"),
        (["smooth", str(tmp_path / "fifo"), *out], "tracks file "),
        (["eval", "--gt", os.devnull, "--res", os.devnull], f"--gt {os.devnull} is not a regular"),
        (["experiment", "gaps", "--gt", os.devnull], f"ground truth {os.devnull} is not a regular"),
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert message in err and "not found" not in err and err.count("\n") == 1, err
    assert sorted(os.listdir(tmp_path)) == ["fifo"]


def test_a_compressed_or_binary_file_is_named_as_such(tmp_path: Path) -> None:
    """Was: "line has a non-number: '\\x1f\\x8b...'" (the bytes of the compressed file)."""
    import bz2
    import gzip
    import lzma
    import zipfile

    text = b"1,1,10,10,5,5,1,-1,-1,-1\n"
    (tmp_path / "t.txt.gz").write_bytes(gzip.compress(text))
    (tmp_path / "t.txt.bz2").write_bytes(bz2.compress(text))
    (tmp_path / "t.txt.xz").write_bytes(lzma.compress(text))
    with zipfile.ZipFile(tmp_path / "t.zip", "w") as z:
        z.writestr("t.txt", text)
    (tmp_path / "nul.txt").write_bytes(text + b"\0\0")
    (tmp_path / "utf32.txt").write_bytes(text.decode().encode("utf-32"))
    for name, message in (
        ("t.txt.gz", "is gzip-compressed, not text; decompress it first"),
        ("t.txt.bz2", "is bzip2-compressed, not text; decompress it first"),
        ("t.txt.xz", "is xz-compressed, not text; decompress it first"),
        ("t.zip", "is zip-compressed, not text; decompress it first"),
        ("nul.txt", "is not a text file (it holds NUL bytes)"),
        ("utf32.txt", "is not a text file (it holds NUL bytes)"),
    ):
        with pytest.raises(ValueError) as exc:
            mot.read_mot(tmp_path / name, what="tracks file")
        assert str(exc.value) == f"tracks file {tmp_path / name} {message}"


def test_a_header_line_gets_a_hint(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A header line (pandas' ``to_csv``, a spreadsheet's export) was refused as any line
    with a non-number, with no word of what to do; a '#' line is a comment, already read."""
    from pftrack.cli import main

    header = "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x,y,z"
    body = "1,1,10,20,30,60,1,-1,-1,-1\n3,1,14,20,30,60,1,-1,-1,-1\n"
    hint = " (a header line? delete it, or start it with # to keep it as a comment)"
    p = tmp_path / "h.txt"
    for text, line in ((f"{header}\n{body}", 1), (f"\n{header.replace(',', ' ')}\r\n{body}", 2)):
        p.write_text(text)
        with pytest.raises(ValueError) as exc:
            mot.read_mot(p, what="tracks file")
        assert str(exc.value).startswith(f"{p}:{line}: tracks file line has a non-number: ")
        assert str(exc.value).endswith(hint)
        p.write_text("#" + text.lstrip())
        assert mot.read_mot(p).shape == (2, 10)  # the way out the hint names
    # only the file's first row may be a header: a word further down is a bad line, no more
    p.write_text(f"{body}{header}\n")
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p)
    assert str(exc.value) == f"{p}:3: MOT file line has a non-number: {header!r}"
    p.write_text(f"{header}\n{body}")
    assert main(["recover", str(p), "--out", str(tmp_path / "o.txt")]) == 2
    err = capsys.readouterr().err
    assert err.endswith(f"{hint}\n") and err.count("\n") == 1, err
    assert not (tmp_path / "o.txt").exists()


def test_kitti_tracking_rows_are_named_as_such(tmp_path: Path) -> None:
    """KITTI's tracking labels (``frame id type truncated occluded alpha x1 y1 x2 y2 ...``, 17
    fields, 18 with a score) were refused with the header hint ("a header line? delete it"):
    deleting the line only moved the refusal to the next one. The message names the layout."""
    kitti = (
        "0 1 Pedestrian 0 0 -10 100.0 120.0 150.0 300.0 1.7 0.6 0.8 1.0 1.6 10.0 0.0\n"
        "1 1 Pedestrian 0 0 -10 102.0 120.0 152.0 300.0 1.7 0.6 0.8 1.0 1.6 10.0 0.0 0.93\n"
    )
    p = tmp_path / "0001.txt"
    for text, line in (
        (kitti, 1),
        ("1 -1 DontCare -1 -1 -10 5 5 20 20 -1 -1 -1 -1000 -1000 -1000 -10\n" + kitti, 1),
        (kitti.split("\n", 1)[1], 1),
    ):
        p.write_text(text)
        with pytest.raises(ValueError) as exc:
            mot.read_mot(p, what="tracks file")
        msg = str(exc.value)
        assert msg.startswith(f"{p}:{line}: tracks file line has a non-number: "), msg
        assert msg.endswith(mot.KITTI_HINT) and "header" not in msg, msg
    # a header line is still told it may be one
    p.write_text("frame id type a b c d e f g h i j k l m n\n" + kitti)
    with pytest.raises(ValueError, match="a header line"):
        mot.read_mot(p)


def test_semicolon_separated_rows_are_named_as_such(tmp_path: Path) -> None:
    """A spreadsheet's CSV export where the decimal mark is a comma separates fields by ';'
    (``1;1;399,5;182;...``): was "line has 1 fields, expected at least 6", or a non-number,
    with no word of the separator."""
    p = tmp_path / "s.txt"
    for text in ("1;1;399;182;121;229\n", "1;1;399,5;182,25;121;229;1\n", "1; 1; 3; 4; 5; 6\n",
                 "2,2,3,4,5,6\n1;1;399;182;121;229;0,9\n"):  # fmt: skip
        p.write_text(text)
        with pytest.raises(ValueError) as exc:
            mot.read_mot(p)
        assert str(exc.value).endswith(mot.SEMICOLON_HINT), str(exc.value)
    p.write_text("frame; id; left; top; width; height\n1; 1; 3; 4; 5; 6\n")  # one hint
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p)
    assert str(exc.value).endswith(mot.SEMICOLON_HINT) and "header" not in str(exc.value)
    p.write_text("1,1,3,4,5,6\n1,1;2,3,4,5,6\n")  # one stray ';': a bad line, no more
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p)
    assert str(exc.value) == f"{p}:2: MOT file line has a non-number: '1,1;2,3,4,5,6'"


def test_a_far_edge_is_named_with_the_sum_that_reaches_it(tmp_path: Path) -> None:
    """Was ``write_mot: row 0 (frame 8, id 1) has width 40: a box's right or bottom edge is
    beyond ±1e+09 px`` (``pftrack smooth`` of boxes near the bound): the width alone is fine,
    left + width is not, and the message gave neither the left nor the edge."""
    row = [8, 1, 999999961.25, 10, 40, 60]
    with pytest.raises(ValueError) as exc:
        mot.write_mot(tmp_path / "t.txt", [row])
    assert str(exc.value) == (
        "write_mot: row 0 (frame 8, id 1) has width 40: a box's right or bottom edge is beyond "
        "±1e+09 px (left + width = 1000000001.25)"
    )
    (tmp_path / "b.txt").write_text("1,2,3,-999999990,5,-20\n")  # negative sizes come first
    with pytest.raises(ValueError, match=r":1: negative box width or height"):
        mot.read_mot(tmp_path / "b.txt")
    (tmp_path / "b.txt").write_text("1,2,3,-999999990,5,20\n2,2,3,999999990,5,20\n")
    with pytest.raises(ValueError) as exc:
        mot.read_mot(tmp_path / "b.txt")
    assert str(exc.value) == (
        f"{tmp_path / 'b.txt'}:2: a box's right or bottom edge is beyond ±1e+09 px (top + "
        "height = 1000000010): '2,2,3,999999990,5,20'"
    )
    assert not (tmp_path / "t.txt").exists()


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be"])
def test_utf16_text_with_its_bom_is_read(tmp_path: Path, encoding: str) -> None:
    """Windows PowerShell 5's ``>`` writes a program's output as UTF-16 with a BOM.

    Was refused as "not a text file (it holds NUL bytes)".
    """
    text = "1,1,10,10,5,5,0.9,-1,-1,-1\r\n\r\n3 1 14.5 10 5 5\r\n# note\r\n4,1,16,10,5,5,\r\n"
    bom = {"utf-16": "", "utf-16-le": "\ufeff", "utf-16-be": "\ufeff"}[encoding]
    (tmp_path / "t.txt").write_bytes((bom + text).encode(encoding))
    (tmp_path / "u.txt").write_text(text, encoding="utf-8")
    got = mot.read_mot(tmp_path / "t.txt")
    assert np.array_equal(got, mot.read_mot(tmp_path / "u.txt"))
    assert got[:, 0].tolist() == [1, 3, 4] and got[1, 2] == 14.5
    assert mot.first_row_fields(tmp_path / "t.txt") == 10
    assert mot.data_line_numbers(tmp_path / "t.txt") == [1, 3, 5]
    # the fast reader and the line reader alike: a bad line is named by its number
    (tmp_path / "bad.txt").write_bytes("\ufeff1,1,10,10,5,5\n2,1,x,10,5,5\n".encode("utf-16-le"))
    with pytest.raises(ValueError, match=r"bad.txt:2: MOT file line has a non-number"):
        mot.read_mot(tmp_path / "bad.txt")


def test_write_refuses_non_finite(tmp_path: Path) -> None:
    a = np.ones((2, 10))
    a[1, 3] = np.nan
    with pytest.raises(ValueError, match="row 1 has (a non-finite value|NaN or inf)"):
        mot.write_mot(tmp_path / "t.txt", a)
    assert not (tmp_path / "t.txt").exists()


def test_write_refuses_ragged_rows_and_text(tmp_path: Path) -> None:
    # was NumPy's "setting an array element with a sequence. The requested array has an
    # inhomogeneous shape after 1 dimensions..."
    with pytest.raises(ValueError, match=r"^write_mot: rows must be a rectangular array of "):
        mot.write_mot(tmp_path / "t.txt", [[1, 1, 1, 1, 1, 1, 1, -1, -1, -1], [2, 1, 1, 1]])
    with pytest.raises(TypeError, match=r"^write_mot: rows must hold real numbers, got dtype"):
        mot.write_mot(tmp_path / "t.txt", [["1", "1", "1", "1", "1", "1"]])
    assert not (tmp_path / "t.txt").exists()


def test_rows_may_come_from_an_iterator(tmp_path: Path) -> None:
    """Was ``write_mot: rows must hold real numbers, got dtype object``: NumPy takes an
    iterator for one object; the hint is ``Iterable[Iterable[float]]``."""
    from pftrack.recovery.linking import filled_mask

    rows = [[1, 1, 10, 10, 5, 5], [2, 1, 11, 10, 5, 5.5]]
    want = tmp_path / "want.txt"
    mot.write_mot(want, rows)
    for k, given in enumerate(
        [
            (r for r in rows),
            map(list, rows),
            (iter(r) for r in rows),  # rows that are iterators too
            map(np.asarray, rows),
        ]
    ):
        out = tmp_path / f"{k}.txt"
        mot.write_mot(out, given)
        assert out.read_bytes() == want.read_bytes()
    assert mot.mot_text(r for r in rows) == want.read_text()
    assert filled_mask(r for r in rows).tolist() == [False, False]  # _check.mot_rows
    mot.write_mot(tmp_path / "none.txt", iter([]))
    assert (tmp_path / "none.txt").read_text() == ""


def test_a_path_given_for_rows_says_to_read_it(tmp_path: Path) -> None:
    with pytest.raises(
        TypeError, match=r"^mot_text: rows is a path \('t\.txt'\); read it with pftrack\.read_mot"
    ):
        mot.mot_text("t.txt")  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("col", "value", "match"),
    [
        (4, -5.0, r"row 1 \(frame 2, id 3\) has width -5: negative box width or height"),
        (5, -0.001, r"row 1 \(frame 2, id 3\) has height -0.001: negative box width or height"),
        (2, 2e9, r"row 1 \(frame 2, id 3\) has left 2e\+09: a box value is beyond ±1e\+09 px"),
        (3, -1e300, r"row 1 \(frame 2, id 3\) has top -1e\+300: a box value is beyond"),
        (0, 0.0, r"row 1 has frame 0, expected an integer in 1\.\.2147483647"),
        (0, 2.0**31, r"row 1 has frame 2147483648, expected an integer in 1\.\."),  # 2.14748e+09
    ],
)
def test_write_refuses_what_read_refuses(
    tmp_path: Path, col: int, value: float, match: str
) -> None:
    """Was: written, then refused by read_mot (``pftrack recover`` of the file, ``eval``)."""
    a = np.array([[1, 1, 10, 20, 30, 40, 1, -1, -1, -1], [2, 3, 10, 20, 30, 40, 1, -1, -1, -1]])
    p = tmp_path / "t.txt"
    p.write_text("earlier\n")
    bad = a.astype(np.float64)
    bad[1, col] = value
    for write in (
        lambda: mot.write_mot(p, bad),
        lambda: mot.write_mot(p, bad[:, :6], exact=True),
    ):
        with pytest.raises(ValueError, match=f"^write_mot: {match}"):
            write()
    assert p.read_text() == "earlier\n"  # refused before anything is written
    assert sorted(x.name for x in tmp_path.iterdir()) == ["t.txt"]  # no temporary left
    with pytest.raises(ValueError, match=f"^mot_text: {match}"):
        mot.mot_text(bad)
    with pytest.raises(ValueError, match="^format_mot_row: row 0 "):
        mot.format_mot_row(bad[1])
    p.write_text(",".join(map(repr, bad[1].tolist())) + "\n")  # the same row, as a file
    with pytest.raises(ValueError, match=r"t\.txt:1: (frame is|negative box|a box value)"):
        mot.read_mot(p)


def test_write_takes_what_read_takes(tmp_path: Path) -> None:
    """The edges of the rule: sizes of 0, values of exactly ±1e9 px, frame 2**31 - 1."""
    a = np.array([[1, 1, -1e9, 1e9, 0, 0], [2**31 - 1, -4, 0, 0, 1e9, 1e9]], dtype=np.float64)
    mot.write_mot(tmp_path / "t.txt", a)
    np.testing.assert_array_equal(mot.read_mot(tmp_path / "t.txt")[:, :6], a)


def test_a_byte_order_mark_is_not_a_field(tmp_path: Path) -> None:
    # Windows editors save UTF-8 with a BOM (was: "line has a non-number: '\ufeff1,...'")
    p = tmp_path / "t.txt"
    p.write_bytes(b"\xef\xbb\xbf1,-1,10,10,8,16,1\r\n2,-1,10,10,8,16,1\r\n")
    got = mot.read_mot(p)
    assert got.shape == (2, 10) and got[:, 0].tolist() == [1.0, 2.0]
    np.testing.assert_array_equal(got, _slow_read(p))
    p.write_bytes(b"\xef\xbb\xbf# comment\n1,-1,10,10,8,16,1\n")  # the line-by-line reader
    assert mot.read_mot(p).shape == (1, 10)


def test_values_read_are_written_unchanged_and_writing_is_a_fixed_point(tmp_path: Path) -> None:
    """Regression: every value was written with 2 decimals (0.99502 -> 1.00, which column 8
    then read as pftrack's interpolated flag) and 88.0 as 88.00 but 88 once read back."""
    p, q = tmp_path / "in.txt", tmp_path / "out.txt"
    text = (
        "1,1,10,20.5,31.03,75.17,0.995616,-4.1554,-7.3591,0\n"
        "1,2,1234.56789,0.0012345,1e-3,99,9999999999,0.99502,-0.099279,-1\n"
        "2,1,88.00,-7.00,1.50,0.10,1.000,-1.0,-1,-1\n"
    )
    p.write_text(text)
    mot.write_mot(q, mot.read_mot(p))
    assert q.read_text().splitlines() == [
        "1,1,10,20.5,31.03,75.17,0.995616,-4.1554,-7.3591,0",
        "1,2,1234.56789,0.0012345,0.001,99,9999999999,0.99502,-0.099279,-1",
        "2,1,88,-7,1.5,0.1,1,-1,-1,-1",
    ]
    np.testing.assert_array_equal(mot.read_mot(q), mot.read_mot(p))
    # computed values: 2 decimals in their shortest form, and the same bytes once read back
    rng = np.random.default_rng(1)
    a = np.column_stack([np.arange(1, 2001), np.ones(2000), rng.normal(0, 300, (2000, 8))])
    a[::5, 2:] = np.round(a[::5, 2:], 2)  # 88.0, 12.5: no trailing zeros
    a[:, 4:6] = np.abs(a[:, 4:6])
    a[::7, 3] = -np.pi * 1e-9  # rounds to 0, never "-0"
    a[::11, 8] = 1e16
    mot.write_mot(q, a)
    first = q.read_bytes()
    back = mot.read_mot(q)
    assert np.abs(back - a).max() <= 0.005 + 1e-9
    mot.write_mot(q, back)
    assert q.read_bytes() == first
    fields = first.decode().replace("\n", ",").split(",")
    assert "-0" not in fields and not any(f.endswith((".00", ".0")) for f in fields)
    assert all(len(f.partition(".")[2]) <= 2 for f in fields)


def test_float32_values_are_written_as_their_float32_digits(tmp_path: Path) -> None:
    """Regression: a detector's float32 score put in a float64 array (supervision's
    ``confidence``, a BoxMOT loop's ``dets``, rows stacked from them) has 16 digits as a double
    and was rounded to 2 decimals (0.9955 -> 1, 0.004 -> 0), so ``Tracker.finalize()`` fed the
    float32 boxes of a det.txt wrote other scores than ``pftrack track`` on that det.txt."""
    single = np.array(
        [
            [1, 1, 649.44, 231.5, 44.42, 86.13, 0.9955, -1, -1, -1],
            [1, 2, 649.4412, 0.1, 3.0000002, 7, 0.004, 0.997784, 123456789, -1],
        ],
        np.float32,
    )
    q = tmp_path / "out.txt"
    mot.write_mot(q, single.astype(np.float64))
    assert q.read_text().splitlines() == [
        "1,1,649.44,231.5,44.42,86.13,0.9955,-1,-1,-1",
        "1,2,649.4412,0.1,3.0000002,7,0.004,0.997784,123456792,-1",  # the float32 integer
    ]
    back = mot.read_mot(q)
    np.testing.assert_array_equal(back.astype(np.float32), single)  # the same float32s
    first = q.read_bytes()
    mot.write_mot(q, back)
    assert q.read_bytes() == first  # a fixed point
    assert mot.mot_text(single) == first.decode()  # a float32 array itself too
    # a float32 too small for its digits within 22 decimals is rounded as before
    assert mot.mot_text(np.array([[1, 1, 1, 2, 3, 4, np.float32(1e-30), -1]])).startswith(
        "1,1,1,2,3,4,0,-1,"
    )
    # doubles that are no float32 (pftrack's computed boxes) keep their 2 decimals
    rng = np.random.default_rng(2)
    a = np.column_stack([np.arange(1, 501), np.ones(500), np.abs(rng.normal(0, 300, (500, 8)))])
    fields = mot.mot_text(a).replace("\n", ",").split(",")
    assert all(len(f.partition(".")[2]) <= 2 for f in fields)


def test_huge_values_are_written_short_and_read_back_equal(tmp_path: Path) -> None:
    """Was: a conf of 1e308 written as a 309-digit integer (``%.0f``)."""
    a = np.array(
        [
            [1, 1, 10, 20, 30, 40, 1e308, -1e20, 2.0**52, 123456789012345678.0],
            [2, 1, 10, 20, 30, 40, 9999999999999998.0, 1e16, 0.5, -1],
        ]
    )
    q = tmp_path / "out.txt"
    for exact in (False, True):
        mot.write_mot(q, a, exact=exact)
        assert q.read_text().splitlines() == [
            "1,1,10,20,30,40,1e+308,-1e+20,4503599627370496,1.2345678901234568e+17",
            "2,1,10,20,30,40,9999999999999998,1e+16,0.5,-1",  # under 1e16: an integer still
        ]
        np.testing.assert_array_equal(mot.read_mot(q), a)


def test_values_of_any_length_are_written_exactly_when_marked(tmp_path: Path) -> None:
    """Regression: values of more than 10 significant digits (``np.savetxt``'s ``%.18e``) were
    rounded to 2 decimals even where they were read from a file (499.1234567891234 -> 499.12).
    """
    a = np.array(
        [
            [1, 1, 499.1234567891234, 10, 20.5, 40, 0.123456789012, -1, -1, -1],
            [1, 2, 1 / 3, 2e-17, 1e8 / 7, 88, 1, 0.99502, 1.0000000000000002, 3e300],
            [2, 1, -0.0, 12.345678901234, 20, 40, 0.5, -1, -1, -1],
        ]
    )
    p, q = tmp_path / "savetxt.txt", tmp_path / "out.txt"
    np.savetxt(p, a, delimiter=",")
    mot.write_mot(q, mot.read_mot(p), exact=True)
    np.testing.assert_array_equal(mot.read_mot(q), a)  # the same doubles
    first = q.read_text()
    assert first.splitlines()[0] == "1,1,499.1234567891234,10,20.5,40,0.123456789012,-1,-1,-1"
    assert "-0" not in first.replace("e-", "")
    mot.write_mot(q, mot.read_mot(q), exact=True)
    assert q.read_text() == first  # a fixed point
    # per row and per value: the rest is rounded as before
    assert mot.mot_text(a, exact=np.array([True, False, False])).splitlines()[2] == (
        "2,1,0,12.35,20,40,0.5,-1,-1,-1"
    )
    cells = np.zeros((3, 7), bool)
    cells[0, 6] = True  # conf of row 0 only (a 7-column array: the defaults are added)
    assert mot.mot_text(a[:, :7], exact=cells).splitlines()[0] == (
        "1,1,499.12,10,20.5,40,0.123456789012,-1,-1,-1"
    )
    assert mot.mot_text(a).splitlines()[0] == "1,1,499.12,10,20.5,40,0.12,-1,-1,-1"  # default
    assert mot.format_mot_row(a[0], exact=True) == first.splitlines()[0]
    with pytest.raises(ValueError, match=r"exact has shape \(2,\)"):
        mot.mot_text(a, exact=np.array([True, False]))
    with pytest.raises(TypeError, match="exact must be a bool"):
        mot.mot_text(a, exact=np.ones(3))


@pytest.mark.parametrize("column", [7, 8, 9, 10])
@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_non_finite_value_in_any_column_is_named_by_file_and_line(
    tmp_path: Path, column: int, value: str
) -> None:
    """Regression: NaN in the score (or x, y, z) columns was read, then refused later by
    the tracker ("dets row 6 contains NaN") or fill_gaps ("row 288 has a non-finite conf")."""
    fields = "2,1,10,20,30,40,0.9,-1,-1,-1".split(",")
    fields[column - 1] = value
    p = tmp_path / "t.txt"
    p.write_text("1,1,10,20,30,40,0.9,-1,-1,-1\n" + ",".join(fields) + "\n")
    name = ("conf", "x", "y", "z")[column - 7]
    with pytest.raises(ValueError, match=rf"t.txt:2: .*non-finite .*column {column} \({name}\)"):
        mot.read_mot(p, what="detection file")


_LATER = (
    "before a value in a later column (optional columns may be left empty only at the end of "
    "a line)"
)


@pytest.mark.parametrize(
    ("text", "column"),
    [
        ("1,,7,10,10,20,40\n3,,7,12,10,20,40\n", "column 2 (id), which needs a number"),
        (",1,10,10,20,40\n", "column 1 (frame), which needs a number"),
        ("1,1,10,10,20,,0.9\n", "column 6 (height), which needs a number"),
        ("1,1,10,10,20,\n", "column 6 (height), which needs a number"),  # was: "5 fields"
        ("1, 1 , ,10,20,40\n", "column 3 (left), which needs a number"),
        # MOT17's 9 columns with an empty conf: the class was read as conf
        ("1,7,10,10,20,40,,1,0.5\n", f"column 7 (conf) {_LATER}"),
        ("3,1,12,10,20,40,,0.5,,\n", f"column 7 (conf) {_LATER}"),
        ("1,1,10,10,20,40,0.9,,,,5\n", f"column 8 (x) {_LATER}"),
    ],
)
def test_an_empty_field_is_refused_never_skipped(tmp_path: Path, text: str, column: str) -> None:
    """Regression: empty fields were dropped and the values after them shifted left, silently
    (``1,,7,10,...`` read as frame 1, id 7, left 10): comma-separated lines keep them now."""
    p = tmp_path / "t.txt"
    p.write_text("# c\n" + text)  # the line-by-line reader (the fast one refuses them too)
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p, what="tracks file")
    first = text.splitlines()[0]
    assert str(exc.value) == f"{p}:2: tracks file line has an empty {column}: {first!r}"
    p.write_text(text)
    with pytest.raises(ValueError, match=f"^{p}:1: tracks file line has an empty column "):
        mot.read_mot(p, what="tracks file")


@pytest.mark.parametrize(
    ("text", "want"),
    [
        ("1,2,10,10,20,40,\n", [1, 2, 10, 10, 20, 40, 1, -1, -1, -1]),  # a trailing comma
        ("1,2,10,10,20,40,,,,\n", [1, 2, 10, 10, 20, 40, 1, -1, -1, -1]),
        ("1,2,10,10,20,40,0.5,-1,,,\n", [1, 2, 10, 10, 20, 40, 0.5, -1, -1, -1]),
        ("1,2,10,10,20,40,0.5,3, , \n", [1, 2, 10, 10, 20, 40, 0.5, 3, -1, -1]),
        ("1, 2 ,10 , 10,20,40 , \r\n", [1, 2, 10, 10, 20, 40, 1, -1, -1, -1]),
        ("1,2 10,10 20,40\n", [1, 2, 10, 10, 20, 40, 1, -1, -1, -1]),  # commas and spaces
        ("1\t2\t10\t10\t20\t40\t0.5\n", [1, 2, 10, 10, 20, 40, 0.5, -1, -1, -1]),
        ("1  2   1e3 10 20 40\r", [1, 2, 1000, 10, 20, 40, 1, -1, -1, -1]),
        ("1,2,10,10,20,40,0.5,1,2,3,,9\n", [1, 2, 10, 10, 20, 40, 0.5, 1, 2, 3]),  # past 10
    ],
)
def test_empty_fields_at_the_end_of_a_line_are_absent_columns(
    tmp_path: Path, text: str, want: list[float]
) -> None:
    """Trailing commas and empty optional columns at the end get the defaults; no shift."""
    p = tmp_path / "t.txt"
    p.write_bytes(b"\xef\xbb\xbf\n" + text.encode())  # a BOM and a blank line: kept working
    assert mot.read_mot(p).tolist() == [want]


def test_every_command_refuses_an_empty_field_by_file_line_and_column(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Was: exit 0, the row read with its values shifted one column left."""
    from pftrack.cli import main
    from pftrack.synthetic import make_scene

    seq = tmp_path / "SEQ"
    make_scene(n_frames=5, rng=0).write_images(seq / "img1")
    (seq / "det").mkdir()
    (seq / "det" / "det.txt").write_text("1,-1,10,10,20,40,1\n2,-1,,10,20,40,1\n")
    (seq / "seqinfo.ini").write_text("[Sequence]\nimWidth=960\n")
    (tmp_path / "good.txt").write_text("1,1,10,10,20,40\n3,1,12,10,20,40\n")
    (tmp_path / "eid.txt").write_text("1,,7,10,10,20,40\n3,,7,12,10,20,40\n")
    monkeypatch.chdir(tmp_path)
    eid = "eid.txt:1: {} line has an empty column 2 (id), which needs a number: "
    size = ["--image-size", "768x576"]
    for argv, message in (
        (["track", "SEQ", "--detections", "auto", "--out", "o.txt"], "SEQ/det/det.txt:2: "
         "detection file line has an empty column 3 (left), which needs a number: "),
        (["recover", "eid.txt", "--out", "o.txt"], eid.format("tracks file")),
        (["smooth", "eid.txt", "--out", "o.txt"], eid.format("tracks file")),
        (["eval", "--gt", "eid.txt", "--res", "good.txt"], eid.format("ground truth")),
        (["eval", "--gt", "good.txt", "--res", "eid.txt"], eid.format("result file")),
        (["render", "SEQ", "eid.txt", "--out", "o.mp4"], eid.format("tracks file")),
        (["experiment", "gaps", "--gt", "eid.txt", *size], eid.format("ground truth")),
        (["experiment", "gaps", "--gt", "good.txt", "eid.txt", *size], eid.format("ground truth")),
    ):  # fmt: skip
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        prog = " ".join(argv[:2]) if argv[0] == "experiment" else argv[0]  # its sub-command
        assert err.startswith(f"pftrack {prog}: error: {message}") and err.count("\n") == 1
    assert sorted(os.listdir(tmp_path)) == ["SEQ", "eid.txt", "good.txt"]
    # many files: the file fails by name, as any bad file of a batch (the others are done)
    assert main(["batch", "SEQ", "--detections", "auto", "--out", "b", "-q"]) == 1
    assert "det.txt:2: detection file line has an empty column 3 (left)" in capsys.readouterr().err


def test_as_written_gives_the_values_read_back_in_the_rows_order(tmp_path: Path) -> None:
    rows = np.array([[2, 1, 10.123456789012, 5.005, 20.0, 40.0], [1, 2, 3.5, 4.25, 6.0, 8.0]])
    mot.write_mot(tmp_path / "t.txt", rows)
    np.testing.assert_array_equal(mot.as_written(rows), mot.read_mot(tmp_path / "t.txt")[::-1])
    assert mot.as_written(np.zeros((0, 6))).shape == (0, 10)


def test_pandas_to_csv_with_its_index_is_named_as_such(tmp_path: Path) -> None:
    """pandas' ``to_csv`` writes an index column and a header by default (``,frame,id,...``,
    then ``0,1,-1,...``): was "an empty column 1 (frame)", and once the header was deleted
    "frame is 0 ... numbered from 0? add 1 to every frame", which would put line k on frame k."""
    p = tmp_path / "det.csv"
    rows = (
        "0,1.0,-1.0,10.0,20.0,5.0,9.0,0.9,-1.0,-1.0,-1.0\n"
        "1,2.0,-1.0,11.0,20.0,5.0,9.0,0.8,-1.0,-1.0,-1.0\n"
    )
    p.write_text(",frame,id,x,y,w,h,conf,a,b,c\n" + rows)
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p, what="detection file")
    msg = str(exc.value)
    assert msg.startswith(f"{p}:1: detection file line has an empty column 1 (frame)"), msg
    assert msg.endswith(mot.INDEX_HEADER_HINT), msg
    p.write_text(rows)  # the header deleted: the index column stays
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p, what="detection file")
    msg = str(exc.value)
    assert msg.startswith(f"{p}:1: frame is 0, expected an integer"), msg
    assert msg.endswith(mot.INDEX_HINT + ")"), msg
    # without the index: the header hint, and frame 0 of 10 fields is told to add 1 alone
    p.write_text(
        "frame,id,x,y,w,h,conf,a,b,c\n" + rows.replace("0,1.0", "1.0").replace("1,2.0", "2.0")
    )
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p)
    assert str(exc.value).endswith(mot.HEADER_HINT)
    p.write_text("0,-1,10,20,5,9,0.9,-1,-1,-1\n")
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p)
    assert "index column" not in str(exc.value) and "add 1 to every frame" in str(exc.value)
    p.write_text(",1,10,20,5,9\n")  # an empty frame, no word: no hint
    with pytest.raises(ValueError) as exc:
        mot.read_mot(p)
    assert str(exc.value).endswith("which needs a number: ',1,10,20,5,9'")
