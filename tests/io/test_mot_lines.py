"""The C++ text kernel ``_core.mot_lines`` writes what Python's ``%`` wrote, byte for byte.

``tests/reference/text.py`` holds the pure-Python formatting ``pftrack.io.mot._lines`` used
before the kernel (``%d``, ``%.{d}f``, ``%r``).
"""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
import pytest

from pftrack import _core
from pftrack.io import mot
from tests.conftest import dataset
from tests.reference import text as reference

CODES = [*range(23), mot._REPR]

#: Values whose text is easy to get wrong: ties of %.{d}f on the exact binary value (0.125,
#: 2.675, x.xx5), the edges of repr's fixed range (1e-4 .. 1e16), integers near 2**53,
#: subnormals, the largest double, powers of 10.
SPECIAL = [
    0.0, -0.0, 0.5, 1.5, 2.5, -2.5, 0.125, 0.375, -0.125, 2.675, 1.005, 1.015, 1.025, 0.045,
    53.485, 12.345, 99.995, 0.1, 0.2, 0.3, 1 / 3, 2 / 3, 1e-05, 1.5e-05, 0.0001, 0.00011,
    9.999999999999999e-05, 1.2345678901234567e-05, 499.1234567891234, 1e16, 9999999999999998.0,
    1e15, 123456789012345678.0, 2.0**53, 2.0**53 - 1, -(2.0**53), 2.0**52 + 0.5, 2.0**63, 1e22,
    1e23, 5e-324, -5e-324, 2.2250738585072014e-308, 2.225073858507201e-308, 1.7976931348623157e308,
    -1.7976931348623157e308, 1e308, 1e-320, 0.30000000000000004, 4.35, 0.615, 1e9, -1e9,
    *(10.0**k for k in range(-320, 309)),
    *(-(10.0**k) for k in range(-30, 30)),
]  # fmt: skip


def _doubles(rng: np.random.Generator, n: int) -> np.ndarray:
    """n doubles over every magnitude: random bit patterns, log-uniform, short decimals."""
    bits = rng.integers(0, 2**63 - 1, n // 3, dtype=np.int64).view(np.float64)
    bits = bits[np.isfinite(bits)] * rng.choice([-1.0, 1.0], bits[np.isfinite(bits)].size)
    logu = 10.0 ** rng.uniform(-320, 308.2, n // 3) * rng.choice([-1.0, 1.0], n // 3)
    digits = rng.integers(0, 6, n - n // 3 * 2)
    short = np.round(rng.normal(0, 1e3, digits.size) * 10.0**digits) / 10.0**digits
    x = np.concatenate([bits, logu, short + np.where(digits % 2, 0.005, 0.0), SPECIAL])
    return x[np.isfinite(x)]


def _table(x: np.ndarray, codes: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """x laid out as (M, 8) values with codes, and random integral ids (M, 2)."""
    m = -(-x.size // 8)
    values = np.resize(x, m * 8).reshape(m, 8)
    dec = np.resize(codes, m * 8).reshape(m, 8).astype(np.int64)
    ids = rng.integers(-(2**53), 2**53, (m, 2), endpoint=True).astype(np.float64)
    ids[: min(m, 4)] = [[1, -1], [2**53, -(2**53)], [-0.0, 0.0], [2**31 - 1, 123]][: min(m, 4)]
    return ids, values, dec


def _check(ids: np.ndarray, values: np.ndarray, dec: np.ndarray) -> None:
    got = _core.mot_lines(ids, values, dec)
    want = reference.mot_lines(ids, values, dec)
    if got != want:  # name the first line that differs, not a 1 MB diff
        g, w = got.splitlines(), want.splitlines()
        k = next(
            (i for i, (a, b) in enumerate(zip(g, w, strict=False)) if a != b), min(len(g), len(w))
        )
        pytest.fail(f"line {k}: C++ {g[k:k + 1]} != Python {w[k:k + 1]}, "
                    f"values {values[k].tolist()}, codes {dec[k].tolist()}")  # fmt: skip


def test_every_code_on_random_rows() -> None:
    rng = np.random.default_rng(1)
    x = _doubles(rng, 40_000)
    x = x[np.abs(x) < 1e40]  # %.22f of 1e308 is 331 characters: those come below, fewer
    codes = rng.choice(CODES, x.size)
    _check(*_table(x, codes, rng))


@pytest.mark.parametrize("code", CODES)
def test_each_code_on_every_magnitude(code: int) -> None:
    rng = np.random.default_rng(code)
    x = np.concatenate([SPECIAL, _doubles(rng, 3000)])
    _check(*_table(x, np.full(x.size, code), rng))


@pytest.mark.parametrize("code", range(9))
def test_exact_ties_round_to_even_as_python_does(code: int) -> None:
    # (k + 1/2) / 2**code is a tie of %.{code}f (and %.{code - 1}f ...): the exact binary value
    # is halfway, and both round it to the even digit (0.125 -> 0.12, 0.375 -> 0.38)
    rng = np.random.default_rng(10 + code)
    x = (rng.integers(-(10**6), 10**6, 4000) + 0.5) / 2.0**code
    codes = np.maximum(code - rng.integers(0, 2, x.size), 0)
    _check(*_table(x, codes, rng))


def test_shortest_form_is_repr() -> None:
    rng = np.random.default_rng(2)
    x = _doubles(rng, 200_000)
    ids, values, dec = _table(x, np.full(x.size, mot._REPR), rng)
    got = _core.mot_lines(ids, values, dec).splitlines()
    want = [",".join([str(int(i)) for i in r[:2]] + [repr(v) for v in r[2:]]) for r in
            np.column_stack([ids, values]).tolist()]  # fmt: skip
    bad = [(g, w) for g, w in zip(got, want, strict=True) if g != w]
    assert not bad, bad[:3]


def test_mot_text_equals_the_python_formatting() -> None:
    rng = np.random.default_rng(3)
    n = 5000
    a = np.column_stack(
        [rng.integers(1, 2**31, n), rng.integers(-(2**53), 2**53, n), rng.normal(0, 300, (n, 8))]
    ).astype(np.float64)
    a[:, 4:6] = np.abs(a[:, 4:6])
    digits = rng.integers(0, 12, (n, 8))
    half = slice(0, n // 2)  # short decimals, as files hold them; the rest pftrack-computed
    a[half, 2:] = np.round(a[half, 2:] * 10.0 ** digits[half]) / 10.0 ** digits[half]
    a[n // 2 : n // 2 + 50, 6:] = rng.choice([1e16, 3e200, 5e-324, 1e-5, -0.0], (50, 4))
    exact = rng.random((n, 10)) < 0.5
    for e in (None, exact, np.ones((n, 10), bool)):
        assert mot._lines(a, e) == reference.lines(a, e)


def _files() -> list[Path]:
    data = dataset("pets09-s2l1")
    files = [data / "gt.txt", data / "det.txt"]
    mot15 = data.parent / "mot15-gt"
    return files + sorted(mot15.glob("*/gt.txt"))


def test_real_files_are_written_as_before(tmp_path: Path) -> None:
    files = _files()
    assert len(files) >= 3
    for f in files:
        a = mot.read_mot(f)
        order = np.lexsort((a[:, mot.ID], a[:, mot.FRAME]))
        for exact in (False, True):
            out = tmp_path / "out.txt"
            mot.write_mot(out, a, exact=exact)
            mask = np.ones(a.shape, bool) if exact else None
            old = reference.lines(a[order], None if mask is None else mask[order])
            assert out.read_bytes() == old.encode(), f"{f} exact={exact}"


def test_no_rows_and_one_row() -> None:
    assert _core.mot_lines(np.zeros((0, 2)), np.zeros((0, 8)), np.zeros((0, 8), np.int64)) == ""
    assert mot.mot_text(np.zeros((0, 10))) == ""
    assert mot.format_mot_row([1, 2, 3.25, 4, 5, 6]) == "1,2,3.25,4,5,6,1,-1,-1,-1"


def test_strided_inputs_are_read_as_their_values() -> None:
    rng = np.random.default_rng(4)
    ids, values, dec = _table(_doubles(rng, 800), rng.choice(CODES, 800), rng)
    want = _core.mot_lines(ids, values, dec)
    wide = np.column_stack([ids, values])
    assert _core.mot_lines(wide[:, :2], wide[:, 2:], np.asfortranarray(dec)) == want


@pytest.mark.parametrize(
    ("ids", "values", "dec", "error", "match"),
    [
        (np.zeros((2, 2), np.int64), np.zeros((2, 8)), np.zeros((2, 8), np.int64), TypeError,
         "ids dtype is int64, expected float64"),
        (np.zeros((2, 2)), np.zeros((2, 8), np.float32), np.zeros((2, 8), np.int64), TypeError,
         "values dtype is float32, expected float64"),
        (np.zeros((2, 2)), np.zeros((2, 8)), np.zeros((2, 8), np.int32), TypeError,
         "decimals dtype is int32, expected int64"),
        (np.zeros((2, 3)), np.zeros((2, 8)), np.zeros((2, 8), np.int64), ValueError,
         r"ids has shape \(2, 3\), expected \(2, 2\)"),
        (np.zeros(2), np.zeros((2, 8)), np.zeros((2, 8), np.int64), ValueError,
         r"ids must be a \(M, 2\) array"),
        (np.zeros((2, 2)), np.zeros((3, 8)), np.zeros((2, 8), np.int64), ValueError,
         r"values has shape \(3, 8\), expected \(2, 8\)"),
        (np.zeros((2, 2)), np.zeros((2, 8)), np.zeros(16, np.int64), ValueError,
         r"decimals has shape \(16,\), expected \(2, 8\)"),
        (np.zeros((2, 2)), np.zeros((2, 8)), np.full((2, 8), 23, np.int64), ValueError,
         r"decimals\[0, 0\] is 23, expected 0..22 or 31"),
        (np.zeros((2, 2)), np.zeros((2, 8)), np.full((2, 8), -1, np.int64), ValueError,
         r"decimals\[0, 0\] is -1"),
        (np.zeros((2, 2)), np.array([[0.0] * 7 + [np.nan]] * 2), np.zeros((2, 8), np.int64),
         ValueError, r"values\[0, 7\] is not finite"),
        (np.zeros((2, 2)), np.full((2, 8), np.inf), np.full((2, 8), 31, np.int64), ValueError,
         r"values\[0, 0\] is not finite"),
        (np.array([[1.0, 0.5], [1, 1]]), np.zeros((2, 8)), np.zeros((2, 8), np.int64), ValueError,
         r"ids\[0, 1\] is 0.5.*, expected an integer"),
        (np.array([[1.0, 1], [2.0**54, 1]]), np.zeros((2, 8)), np.zeros((2, 8), np.int64),
         ValueError, r"ids\[1, 0\] is .*expected an integer with \|v\| <= 2\*\*53"),
    ],
)  # fmt: skip
def test_bad_arguments_are_named(
    ids: np.ndarray, values: np.ndarray, dec: np.ndarray, error: type, match: str
) -> None:
    with pytest.raises(error, match=f"^mot_lines: {match}"):
        _core.mot_lines(ids, values, dec)


def test_threads_give_the_serial_result() -> None:
    rng = np.random.default_rng(5)
    args = _table(_doubles(rng, 80_000), rng.choice(CODES, 80_000), rng)
    want = _core.mot_lines(*args)
    got: list[str] = [""] * 4

    def run(k: int) -> None:
        got[k] = _core.mot_lines(*args)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert got == [want] * 4


@pytest.mark.parametrize(
    "limit, most", [(1e10, mot.MOST_DECIMALS), (1e15, 2), (2.0**53, 22), (1.0, 0), (1e3, 5)]
)
def test_fewest_decimals_is_the_numpy_search(limit: float, most: int) -> None:
    """``_core.fewest_decimals`` against the NumPy search ``_decimals`` ran before it."""
    rng = np.random.default_rng(6)
    x = np.concatenate([_doubles(rng, 150_000), [np.nan, np.inf, -np.inf]])
    x = x[rng.permutation(x.size)]
    got = _core.fewest_decimals(x, limit, most)
    want = reference.decimals(x, limit, most)
    bad = np.flatnonzero(got != want)
    assert not bad.size, f"{bad.size} differ, first {x[bad[0]]!r}: {got[bad[0]]} != {want[bad[0]]}"
    assert got.dtype == np.int64 and set(np.unique(got).tolist()) <= set(range(-1, most + 1))
    if most == mot.MOST_DECIMALS:  # every decimal count is met, and values beyond the limit
        assert set(np.unique(got).tolist()) == set(range(-1, most + 1))
    # a strided view is read as its values
    assert np.array_equal(_core.fewest_decimals(x[::3], limit, most), got[::3])


def test_fewest_decimals_of_what_files_hold() -> None:
    held = np.array([88.0, 12.5, 0.1, 53.485, -0.0, 1 / 3])
    assert _core.fewest_decimals(held, 1e10, 22).tolist() == [0, 1, 1, 3, 0, -1]
    assert _core.fewest_decimals(np.zeros(0), 1e10, 22).shape == (0,)


@pytest.mark.parametrize(
    "args, error, match",
    [
        ((np.zeros(3, np.float32), 1e10, 2), TypeError, "values dtype is float32"),
        ((np.zeros((2, 2)), 1e10, 2), ValueError, "values must be a 1-D array"),
        ((np.zeros(3), 0.0, 2), ValueError, "limit is 0"),
        ((np.zeros(3), 2.0**54, 2), ValueError, "limit is"),
        ((np.zeros(3), np.nan, 2), ValueError, "limit is nan"),
        ((np.zeros(3), 1e10, 23), ValueError, "most is 23"),
        ((np.zeros(3), 1e10, -1), ValueError, "most is -1"),
    ],
)
def test_fewest_decimals_bad_arguments(args: tuple, error: type, match: str) -> None:
    with pytest.raises(error, match=f"^fewest_decimals: {match}"):
        _core.fewest_decimals(*args)
