// MOTChallenge text lines (python/pftrack/io/mot.py::_lines): frame and id as integers, then
// 8 values each with its own number of decimals ("%.{d}f") or in its shortest round-trip form
// (Python's repr), byte for byte as Python's `%` formats them.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <system_error>

#include "pftrack/check.hpp"

namespace pftrack {

/// Decimals code of a value written in its shortest round-trip form (mot.py's `_REPR`).
constexpr std::int64_t kReprCode = 31;
/// Most decimals of a "%.{d}f" code (mot.py's MOST_DECIMALS: 10^22 is the largest exact power).
constexpr std::int64_t kMostDecimals = 22;

namespace detail {

/// 10^d for d = 0 .. kMostDecimals, each exact in double (the literals are exact).
inline constexpr double kPow10[kMostDecimals + 1] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// Python's repr(x) of a finite double at `out` (room for 32 chars); returns the end.
/// The shortest round-trip digits (std::to_chars, Ryu) laid out as float_repr_style "short"
/// does: fixed notation when the decimal exponent e of d.ddd x 10^e is in -4..15 (a trailing
/// ".0" on integers), else d.ddde+XX with at least two exponent digits.
inline char* write_repr(char* out, double x) {
    char sci[32];
    const auto r = std::to_chars(sci, sci + sizeof sci, x, std::chars_format::scientific);
    const char* p = sci;
    const char* const end = r.ptr;
    const char* const e_pos = static_cast<const char*>(std::memchr(sci, 'e', static_cast<std::size_t>(end - sci)));
    int exp10 = 0;
    std::from_chars(e_pos + (e_pos[1] == '+' ? 2 : 1), end, exp10);
    if (exp10 < -4 || exp10 >= 16) {  // exponent form: to_chars' scientific layout is Python's
        std::memcpy(out, sci, static_cast<std::size_t>(end - sci));
        return out + (end - sci);
    }
    if (*p == '-') *out++ = *p++;
    char digits[24];  // the significant digits without the point
    int n = 0;
    for (; p < e_pos; ++p)
        if (*p != '.') digits[n++] = *p;
    const int point = exp10 + 1;  // digits before the decimal point (<= 0: leading zeros)
    if (point <= 0) {
        *out++ = '0';
        *out++ = '.';
        for (int k = 0; k < -point; ++k) *out++ = '0';
        std::memcpy(out, digits, static_cast<std::size_t>(n));
        return out + n;
    }
    if (point < n) {
        std::memcpy(out, digits, static_cast<std::size_t>(point));
        out += point;
        *out++ = '.';
        std::memcpy(out, digits + point, static_cast<std::size_t>(n - point));
        return out + (n - point);
    }
    std::memcpy(out, digits, static_cast<std::size_t>(n));
    out += n;
    for (int k = n; k < point; ++k) *out++ = '0';
    *out++ = '.';
    *out++ = '0';
    return out;
}

/// "%.{d}f" of a finite double at `out` (room for 360 chars); returns the end. Python and
/// std::to_chars both round the exact binary value of x to d decimals, ties to even. Fast path:
/// p = x * 10^d is one correctly rounded product (10^d is exact for d <= 22), within half an ulp
/// of the exact one; when |p| < 2^52, p - rint(p) is exact and a multiple of p's ulp (or p is
/// below 1), so if it is not exactly 1/2 the exact product is strictly nearer rint(p) too, and
/// rint(p) is the correctly rounded digits. A product that is a tie in double (the exact one
/// may lie on either side) or too large goes to std::to_chars (Ryu printf).
inline char* write_fixed(char* out, double x, int d) {
    const double p = x * kPow10[d];
    const double n = std::nearbyint(p);
    if (!(std::fabs(p) < 4503599627370496.0) || std::fabs(p - n) == 0.5)
        return std::to_chars(out, out + 360, x, std::chars_format::fixed, d).ptr;
    if (std::signbit(x)) *out++ = '-';  // "-0.00" for -0.001 and -0.0, as Python writes them
    char digits[24];
    const int len = static_cast<int>(
        std::to_chars(digits, digits + sizeof digits, static_cast<std::uint64_t>(std::fabs(n))).ptr -
        digits);
    if (d == 0) {
        std::memcpy(out, digits, static_cast<std::size_t>(len));
        return out + len;
    }
    if (len <= d) {  // 0.000ddd
        *out++ = '0';
        *out++ = '.';
        for (int k = len; k < d; ++k) *out++ = '0';
        std::memcpy(out, digits, static_cast<std::size_t>(len));
        return out + len;
    }
    std::memcpy(out, digits, static_cast<std::size_t>(len - d));
    out += len - d;
    *out++ = '.';
    std::memcpy(out, digits + len - d, static_cast<std::size_t>(d));
    return out + d;
}

}  // namespace detail

/// The fewest decimals d <= `most` (at most kMostDecimals) that print each of the `n` values
/// exactly, or -1, into `out` (mot.py's `_decimals`, the same operations in the same order):
/// d prints v exactly when v == rint(v * 10^d) / 10^d (in double; 10^d exact) and
/// |rint(v * 10^d)| < `limit`. The first d that fails the bound ends the search (|rint| only
/// grows with d). NaN gives -1.
inline void fewest_decimals(const double* v, std::int64_t n, double limit, int most,
                            std::int64_t* out) {
    for (std::int64_t i = 0; i < n; ++i) {
        const double x = v[i];
        std::int64_t d = -1;
        for (int k = 0; k <= most; ++k) {
            double r = std::nearbyint(k ? x * detail::kPow10[k] : x);
            if (!(std::fabs(r) < limit)) break;
            if (k) r /= detail::kPow10[k];
            if (r == x) {
                d = k;
                break;
            }
        }
        out[i] = d;
    }
}

/// The lines of M rows: `ids` (M, 2) frame and id, integral doubles with |v| <= 2^53; `values`
/// (M, 8) finite doubles; `decimals` (M, 8) codes, 0..22 ("%.{d}f") or kReprCode (repr). All
/// row-major and contiguous. Each line is "frame,id,v1,...,v8\n". Throws std::invalid_argument
/// naming the first bad entry (a non-integral or too large id, a non-finite value, a bad code).
inline std::string mot_lines(const double* ids, const double* values,
                             const std::int64_t* decimals, std::int64_t rows) {
    const char* fn = "mot_lines";
    std::string out;
    // Longest value: "%.22f" of 1e308 is 332 chars; a line of typical values is ~45.
    constexpr std::size_t kValueRoom = 360;
    std::size_t size = 0;
    out.resize(static_cast<std::size_t>(rows) * 48 + 10 * kValueRoom);
    for (std::int64_t i = 0; i < rows; ++i) {
        if (out.size() - size < 10 * kValueRoom) out.resize(out.size() * 2 + 10 * kValueRoom);
        char* p = out.data() + size;
        for (int j = 0; j < 2; ++j) {
            const double v = ids[2 * i + j];
            if (!(std::fabs(v) <= 9007199254740992.0 && v == std::nearbyint(v)))
                fail(fn, "ids[" + std::to_string(i) + ", " + std::to_string(j) + "] is " +
                             std::to_string(v) + ", expected an integer with |v| <= 2**53");
            p = std::to_chars(p, p + 24, static_cast<std::int64_t>(v)).ptr;  // %d
            *p++ = ',';
        }
        for (int j = 0; j < 8; ++j) {
            const double v = values[8 * i + j];
            const std::int64_t d = decimals[8 * i + j];
            if (!std::isfinite(v))
                fail(fn, "values[" + std::to_string(i) + ", " + std::to_string(j) +
                             "] is not finite");
            if (d == kReprCode) {
                p = detail::write_repr(p, v);
            } else if (d >= 0 && d <= kMostDecimals) {
                p = detail::write_fixed(p, v, static_cast<int>(d));
            } else {
                fail(fn, "decimals[" + std::to_string(i) + ", " + std::to_string(j) + "] is " +
                             std::to_string(d) + ", expected 0..22 or 31 (shortest form)");
            }
            *p++ = j < 7 ? ',' : '\n';
        }
        size = static_cast<std::size_t>(p - out.data());
    }
    out.resize(size);
    return out;
}

}  // namespace pftrack
