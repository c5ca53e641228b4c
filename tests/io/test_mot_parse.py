"""read_mot's C++ parser (``_core.parse_mot_text``) against ``np.loadtxt``, the reader it replaced.

Whatever the parser takes, it reads bit for bit as ``np.loadtxt`` does; and ``read_mot`` gives
the same array, or the same error, with the parser as without it (``np.loadtxt`` for every file).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from pftrack import _core
from pftrack.io import mot


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.int64)


def _outcome(read: Callable[[], np.ndarray]) -> tuple[str, object, list[str]]:
    """("ok", the array's bits and shape, warnings) or ("error", type and message, warnings)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            a = read()
        except (ValueError, OSError) as e:
            return "error", (type(e).__name__, str(e)), [str(w.message) for w in caught]
    return "ok", (a.shape, _bits(a).tobytes()), [str(w.message) for w in caught]


def _same_as_loadtxt(p: Path, data: bytes, monkeypatch: pytest.MonkeyPatch) -> bool:
    """Assert the parser's rows are loadtxt's and read_mot's outcome is the same without it.

    Returns whether the parser took the text.
    """
    p.write_bytes(data)
    got = _core.parse_mot_text(data)
    if got is not None:
        want = mot._loadtxt(p, "utf-8-sig")
        assert want is not None, data
        assert got.shape == want.shape, data
        assert got.dtype == np.float64 and got.flags.c_contiguous
        assert np.array_equal(_bits(got), _bits(want)), data
    new = _outcome(lambda: mot.read_mot(p, warn_extra=True))
    with monkeypatch.context() as m:
        m.setattr(mot._core, "parse_mot_text", lambda text: None)
        old = _outcome(lambda: mot.read_mot(p, warn_extra=True))
    assert new == old, data
    return got is not None


_VALUES = st.one_of(
    st.integers(-(10**12), 10**12).map(str),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.floats(-1e4, 1e4).map(lambda v: f"{v:.2f}"),
    st.floats(allow_nan=False, allow_infinity=False).map(lambda v: f"{v:.18e}"),
    st.floats(allow_nan=False, allow_infinity=False, allow_subnormal=True).map(lambda v: f"{v:g}"),
    # digit strings of any length and exponent: the rounding of long and halfway values
    st.tuples(st.text("0123456789", min_size=1, max_size=30), st.integers(0, 30),
              st.integers(-330, 330)).map(lambda t: f"{t[0][:t[1]]}.{t[0][t[1]:]}e{t[2]}"),
    # around the C++ fast path's limits: significands near 2**53, powers of ten near +-22
    st.tuples(st.integers(0, 2**54), st.integers(-26, 26)).map(lambda t: f"{t[0]}e{t[1]}"),
    st.tuples(st.integers(2**53 - 9, 2**53 + 9), st.integers(0, 16)).map(
        lambda t: f"{str(t[0])[:t[1]]}.{str(t[0])[t[1]:]}"),
)  # fmt: skip
_ODD = st.one_of(
    st.text("0123456789.+-eE", min_size=1, max_size=6),  # number-like, mostly not numbers
    st.sampled_from(["nan", "inf", "-inf", "NaN", "1e400", "-1e400", "1e-400", "5e-324",
                     "2.2250738585072014e-308", "1_0", "\uff11", "0x10", "1e", ".", "-.5",
                     "+.5", "5.", "+-5", "-0", "", " ", "#", "1" + "0" * 400]),
)  # fmt: skip
_SEPS = st.sampled_from([",", ",", ",", " ", "\t", ", ", " ,", "  ", ",,", " \t "])
_ENDS = st.sampled_from(["\n", "\n", "\n", "\r\n", "\r", "\n\n", "\n  \n", "\n# c\n", "\r\r\n"])


@st.composite
def _mot_texts(draw: st.DrawFn) -> bytes:
    """MOT-like text: rows of 4..12 fields, mostly well formed, odd bits mixed in (1 in `odd`)."""
    odd = draw(st.sampled_from([0, 3, 10, 50]))  # 0: none
    rare = st.integers(1, max(odd, 1)).map(lambda k: k == 1 and odd > 0)
    odd_file = draw(rare)
    cols = draw(st.integers(4, 12) if odd_file else st.integers(6, 10))
    sep = draw(_SEPS if odd_file else st.sampled_from([",", " ", "\t", ", "]))
    end = draw(_ENDS if odd_file else st.sampled_from(["\n", "\r\n"]))
    lines = []
    for _ in range(draw(st.integers(0, 6))):
        k = draw(st.integers(0, 12)) if draw(rare) else cols  # a ragged line
        frame = draw(_ODD if draw(rare) else st.integers(1, 10**4).map(str))
        fields = [frame, *(draw(_ODD if draw(rare) else st.one_of(_VALUES, st.integers(
            0, 500).map(str))) for _ in range(k - 1))]  # fmt: skip
        lines.append(draw(_SEPS if draw(rare) else st.just(sep)).join(fields[:k]))
        lines.append(draw(_ENDS) if draw(rare) else end)
    text = "".join(lines)
    if draw(st.booleans()):
        text = text.rstrip("\n")  # no newline at the end
    head = draw(st.sampled_from(["\ufeff", "\n", "  \n", "# c\n"]) if draw(rare) else
                st.sampled_from(["", "", "\ufeff", "\n"]))  # fmt: skip
    return (head + text).encode()


@settings(
    max_examples=int(os.environ.get("PFTRACK_PARSE_EXAMPLES", "300")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(_mot_texts())
@example(b"1,2,3,4,5,6\n")
@example(b"\xef\xbb\xbf1,2,3.5,4,5,6,0.9,-1,-1,-1\r\n2,3,4,5,6,7,1,-1,-1,-1\r\n")
def test_parser_reads_as_loadtxt(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, data: bytes
) -> None:  # fmt: skip
    event(f"parser took it: {_same_as_loadtxt(tmp_path / 't.txt', data, monkeypatch)}")


@pytest.mark.parametrize(
    ("text", "taken"),
    [
        ("", True),
        ("\n\n\r\n", True),
        ("1,2,3,4,5,6\n", True),
        ("1,2,3,4,5,6", True),  # no newline at the end
        ("1,2,3,4,5,6\r\n2,2,3,4,5,6\r\n", True),
        ("1,2,3,4,5,6\r", True),  # a lone '\r' at the end: a line end to both
        ("1,2,3,4,5,6\r2,2,3,4,5,6\r", False),  # lone '\r' line ends (old Mac): loadtxt's
        ("\ufeff1,2,3,4,5,6\n", True),
        ("1,2,3,4,5,6\n\ufeff2,2,3,4,5,6\n", False),
        ("1 2 3 4 5 6\n2\t2  3 4 5 6 \n", True),
        ("  1 2 3 4 5 6\n", True),
        (" 1 , 2,3\t,4,5,6 \n", True),
        ("1,2,3,4,5,6\n\n\n2,2,3,4,5,6\n\n", True),
        ("1,2,3,4,5,6\n  \n2,2,3,4,5,6\n", False),  # a line of blanks
        ("1 2 3 4 5 6\n  \n2 2 3 4 5 6\n", False),
        ("\n  \n1,2,3,4,5,6\n", False),
        ("# c\n1,2,3,4,5,6\n", False),
        ("1,2,3,4,5,6 # c\n", False),
        ("1,2,3,4,5,6,\n", False),  # trailing comma: the line reader's default columns
        ("1,2,3,4,5,6,0.9,,,\n", False),
        ("1,,3,4,5,6\n", False),
        ("1,2,3,4,5,6\n2,2,3,4,5,6,7\n", False),
        ("1 2 3 4 5 6\n2,2,3,4,5,6\n", False),
        ("1,2,3,4,5\n", False),
        ("1,2,3,4,5,6,7,8,9,10,11\n", False),  # warn_extra's
        ("frame,id,left,top,width,height\n1,2,3,4,5,6\n", False),
        ("1,2,nan,4,5,6\n", False),
        ("1,2,inf,4,5,6\n", False),
        ("1,2,1e400,4,5,6\n", False),
        ("1,2,1e-400,4,5,6\n", False),  # loadtxt: 0.0
        ("1,2,5e-320,4,5,6\n", False),  # subnormal
        ("1,2,0e-400,4,5,6\n", True),
        ("1,2,-0,4,5,6\n", True),
        ("1,2,+-3,4,5,6\n", False),
        ("1,2,-+3,4,5,6\n", False),
        ("1,2,1_0,4,5,6\n", False),
        ("1,2,\uff11,4,5,6\n", False),
        ("1,2,0x1p3,4,5,6\n", False),
        ("1,2,3,4,5,6\x0c\n", False),
        ("1,2,3,4,5,6\x00\n", False),
        ("1.5,2,3,4,5,6\n", True),  # read, then refused by the checks as before
        ("0,2,3,4,5,6\n", True),
        ("1,2,3,4,-5,6\n", True),
        ("1,2,3,4,5," + "1" * 400 + "\n", False),  # 1.1e399: loadtxt's inf
        ("1,2,3,4,5," + "1" * 300 + "\n", True),
        ("1,2,3,4,5,0." + "9" * 400 + "\n", True),
        ("1,2,3.14159265358979323846264338327950288,4,5,6\n", True),
        ("1,2,9007199254740993,4,5,6\n", True),  # a tie: rounds to even
        ("1,2,1.7976931348623157e308,4,5,6\n", True),
        ("1,2,9007199254740992,4,5,6\n", True),  # 2**53: the fast path's largest significand
        ("1,2,9007199254740993e-22,4,5,6\n", True),
        ("1,2,1e22,4,5,6\n", True),
        ("1,2,1e23,4,5,6\n", True),  # past 10**22: from_chars
        ("1,2,123456789e-22,4,5,6\n", True),
        ("1,2,123456789e-23,4,5,6\n", True),
        ("1,2,0.1234567890123456789,4,5,6\n", True),  # 19 digits
        ("1,2,1.e3,4,5,6\n", True),
        ("1,2,1e+05,4,5,6\n", True),
        ("1,2,1e00000000005,4,5,6\n", True),
        ("1,2,1e,4,5,6\n", False),
        ("1,2,1e+,4,5,6\n", False),
        ("1,2,.e3,4,5,6\n", False),
        ("1,2,1.7976931348623159e308,4,5,6\n", False),  # rounds to inf
    ],
)
def test_hand_written_texts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, text: str, taken: bool
) -> None:
    data = text.encode()
    assert _same_as_loadtxt(tmp_path / "t.txt", data, monkeypatch) == taken


def test_many_values_round_as_loadtxt(tmp_path: Path) -> None:
    """70 000 values of every magnitude and several layouts, each bit for bit loadtxt's."""
    rng = np.random.default_rng(7)
    n = 10_000
    v = np.concatenate([
        rng.normal(0, 500, n), np.round(rng.uniform(-2e3, 2e3, n), 2),
        rng.uniform(-1, 1, n) * 10.0 ** rng.integers(-307, 308, n),
        rng.integers(-(2**62), 2**62, n).astype(np.float64) + rng.uniform(0, 1, n),
    ])  # fmt: skip
    digits = rng.integers(1, 26, n)
    texts = ["".join(rng.choice(list("0123456789"), d)) for d in digits]
    longs = [f"{t[: len(t) // 2]}.{t[len(t) // 2 :]}e{e}" for t, e in
             zip(texts, rng.integers(-320, 300, n), strict=True)]  # fmt: skip
    # the fast path's edges: significands up to 2**53, powers of ten up to +-22
    m, e = rng.integers(0, 2**54, n).tolist(), rng.integers(-24, 25, n).tolist()
    shorts = [f"{a}e{b}" for a, b in zip(m, e, strict=True)]
    x = v.tolist()
    words = (
        [repr(f) for f in x]
        + [f"{f:.18e}" for f in x]
        + [f"{f:.6f}" for f in x[:n]]
        + longs
        + shorts
    )
    values = np.array([float(w) for w in words])
    keep = (values == 0) | np.isfinite(values) & (np.abs(values) >= 2.2250738585072014e-308)
    words = [w for w, k in zip(words, keep, strict=True) if k]
    words += ["0"] * (-len(words) % 8)
    rows = np.array(words, dtype=object).reshape(-1, 8)
    text = "".join(f"1,2,{','.join(r)}\n" for r in rows).encode()
    p = tmp_path / "t.txt"
    p.write_bytes(text)
    got = _core.parse_mot_text(text)
    want = mot._loadtxt(p, "utf-8-sig")
    assert got is not None and want is not None
    assert got.shape == want.shape == (len(rows), 10)
    assert np.array_equal(_bits(got), _bits(want))
