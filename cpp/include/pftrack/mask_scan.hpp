// Skipping the background of a mask: most of a foreground mask's bytes are 0.
#pragma once

#include <cstdint>
#include <cstring>

#include "types.hpp"

namespace pftrack {
namespace detail {

/// The first x' >= x, in steps of 8 bytes, at which p[x', x' + 8) is not all 0 or x' + 8 > n:
/// where a loop testing one 8-byte word a step stops. Four words a step first (a quarter of
/// the tests and branches on a mask's empty rows), then one.
inline Index skip_zero_words(const std::uint8_t* p, Index x, Index n) {
    std::uint64_t w[4];
    while (x + 32 <= n) {
        std::memcpy(w, p + x, 32);
        if ((w[0] | w[1] | w[2] | w[3]) != 0) break;
        x += 32;
    }
    while (x + 8 <= n) {
        std::memcpy(w, p + x, 8);
        if (w[0] != 0) break;
        x += 8;
    }
    return x;
}

}  // namespace detail
}  // namespace pftrack
