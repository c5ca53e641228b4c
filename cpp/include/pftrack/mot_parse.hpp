// Reading MOTChallenge text (python/pftrack/io/mot.py::_read_fast): the common layout of a
// file parsed in one pass, to the doubles np.loadtxt gives for it; anything else is declined
// (std::nullopt) and goes to np.loadtxt and the line-by-line reader, which name its faults.
#pragma once

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>
#include <system_error>

#include "pftrack/types.hpp"

namespace pftrack {

namespace detail {

/// Smallest normal double: a nonzero value below it (subnormal, or 0 from underflow) is
/// declined, so that only plainly representable values rest on std::from_chars' rounding.
constexpr double kMinNormal = 2.2250738585072014e-308;

inline bool is_blank(char c) { return c == ' ' || c == '\t'; }

/// 10^k for k = 0..22, each exact in double.
inline constexpr double kExactPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                           1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                           1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// Clinger's fast path: `digits` [0-9]* ["." [0-9]*] [("e"|"E") ["+"|"-"] [0-9]+] in [p, end),
/// at least one digit before the exponent, whose significand m (all its digits as an integer,
/// at most 19 of them) is at most 2^53 and whose power of ten e is in -22..22: then m and 10^|e|
/// are exact doubles, and one correctly rounded product or quotient is the correctly rounded
/// value of the text, which strtod and std::from_chars give. False for anything else.
inline bool parse_simple(const char* p, const char* end, double& out) {
    std::uint64_t m = 0;
    int n = 0;     // significand digits
    int frac = 0;  // of them after the point
    for (; p < end && *p >= '0' && *p <= '9'; ++p, ++n) m = m * 10 + std::uint64_t(*p - '0');
    if (p < end && *p == '.')
        for (++p; p < end && *p >= '0' && *p <= '9'; ++p, ++n, ++frac)
            m = m * 10 + std::uint64_t(*p - '0');
    if (n == 0 || n > 19) return false;  // 19 digits: no uint64 overflow
    int e = 0;
    if (p < end && (*p == 'e' || *p == 'E')) {
        ++p;
        const bool minus = p < end && *p == '-';
        if (p < end && (*p == '-' || *p == '+')) ++p;
        int k = 0;
        for (; p < end && *p >= '0' && *p <= '9' && k < 4; ++p, ++k) e = e * 10 + (*p - '0');
        if (k == 0) return false;
        if (minus) e = -e;
    }
    if (p != end || m > (std::uint64_t(1) << 53)) return false;
    e -= frac;
    if (e < -22 || e > 22) return false;
    const double v = static_cast<double>(m);  // exact: m <= 2^53
    out = e < 0 ? v / kExactPow10[-e] : v * kExactPow10[e];
    return true;
}

/// One number in [p, end) with nothing else (the caller strips the separators): an optional
/// sign, then what std::from_chars reads (correctly rounded, as Python's strtod, so bit for bit
/// what np.loadtxt gives), by parse_simple when it can; false for anything else or a value out
/// of range (to the caller's general reader: np.loadtxt reads 1e400 as inf and 1e-400 as 0,
/// both never returned here).
inline bool parse_number(const char* p, const char* end, double& out) {
    const bool plus = p < end && *p == '+';
    if (plus) ++p;  // from_chars takes '-' only (and "+-5" is no number)
    const bool minus = !plus && p < end && *p == '-';
    const char* digits = minus ? p + 1 : p;
    if (digits == end || !((*digits >= '0' && *digits <= '9') || *digits == '.')) return false;
    if (parse_simple(digits, end, out)) {
        if (minus) out = -out;  // exact; "-0" is -0.0, as strtod reads it
        return true;
    }
    const auto r = std::from_chars(p, end, out, std::chars_format::general);
    if (r.ec != std::errc() || r.ptr != end) return false;
    return out == 0.0 || out >= kMinNormal || out <= -kMinNormal;
}

}  // namespace detail

/// The rows of MOTChallenge text `text` (a file's bytes) as an (M, K) array, K = 6..10 the
/// columns of every row, or std::nullopt for a text not of the common layout. That layout: an
/// optional UTF-8 byte-order mark, then lines ending in "\n" or "\r\n" (or a '\r' ending the
/// text; another lone '\r', a line end to Python, is refused: it lies in a field);
/// comma-separated when the first non-empty line has a comma (spaces and tabs around a field
/// allowed), else separated by runs of spaces and tabs; every field a number
/// (detail::parse_number: so no letter but an exponent's e, no '#', control or non-ASCII byte
/// anywhere), none empty (two commas in a row, a trailing comma), no line of only blanks,
/// the same K on every line. Empty lines are skipped; no row at all gives (0, 10), as mot.py's
/// empty file. For such a text the array is bit for bit np.loadtxt's (that delimiter, ndmin=2,
/// comments=None); the caller checks frames, finiteness and boxes as it checks loadtxt's.
inline std::optional<RowMatrixXd> parse_mot_text(std::string_view text) {
    const char* p = text.data();
    const char* const end = p + text.size();
    if (text.size() >= 3 && std::memcmp(p, "\xef\xbb\xbf", 3) == 0) p += 3;  // utf-8-sig
    RowMatrixXd out;  // sized at the first row: a row per line at most (rows <= lines)
    int delimiter = -1;  // ',' or ' ' (runs of blanks), from the first row
    Eigen::Index cols = 0;
    Eigen::Index rows = 0;
    double row[10];
    while (p < end) {
        const auto* eol = static_cast<const char*>(
            std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
        const char* next = eol ? eol + 1 : end;
        const char* line_end = eol ? eol : end;
        if (line_end > p && line_end[-1] == '\r') --line_end;  // "\r\n"
        if (line_end == p) {  // an empty line: np.loadtxt skips it
            p = next;
            continue;
        }
        if (delimiter < 0)
            delimiter = std::memchr(p, ',', static_cast<std::size_t>(line_end - p)) ? ',' : ' ';
        Eigen::Index k = 0;  // fields of the line, up to 10 (more: not the common layout)
        const char* q = p;
        if (delimiter == ',') {
            for (;; ++k) {
                const char* f_end = q;
                while (f_end < line_end && *f_end != ',') ++f_end;
                const char* a = q;
                const char* b = f_end;
                while (a < b && detail::is_blank(*a)) ++a;
                while (b > a && detail::is_blank(b[-1])) --b;
                if (k == 10 || !detail::parse_number(a, b, row[k])) return std::nullopt;
                if (f_end == line_end) break;  // empty fields refused above: a trailing comma
                q = f_end + 1;
            }
            ++k;
        } else {
            for (;; ++k) {
                while (q < line_end && detail::is_blank(*q)) ++q;
                if (q == line_end) break;
                const char* f_end = q;
                while (f_end < line_end && !detail::is_blank(*f_end)) ++f_end;
                if (k == 10 || !detail::parse_number(q, f_end, row[k])) return std::nullopt;
                q = f_end;  // a comma is refused above: in a field
            }
        }
        if (rows == 0) {
            if (k < 6) return std::nullopt;  // only blanks too
            cols = k;
            // every later line holds 2 cols bytes at least (fields, separators, '\n')
            const auto lines = std::count(next, end, '\n') + 1;
            out.resize(std::min<Eigen::Index>(lines, (end - next) / (2 * cols) + 1) + 1, cols);
        } else if (k != cols || rows == out.rows()) {  // the second never: the bound above
            return std::nullopt;
        }
        std::copy(row, row + cols, out.row(rows).data());
        ++rows;
        p = next;
    }
    if (rows == 0) return RowMatrixXd(0, 10);
    out.conservativeResize(rows, cols);  // row-major, same columns: realloc, no copy
    return out;
}

}  // namespace pftrack
