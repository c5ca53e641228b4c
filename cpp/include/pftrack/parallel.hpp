// Independent pieces of work on a few threads, for kernels that the caller runs with the GIL
// released. Each piece writes only its own output, so the results do not depend on the number
// of threads or on which thread ran which piece.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "pftrack/types.hpp"

namespace pftrack {

/// Calls fn(i) for i = 0 .. n - 1 on up to `threads` threads (the caller's among them), handing
/// out indices in order. The first exception thrown by a call stops the hand-out and is rethrown
/// here once every thread has finished.
template <class Fn>
void parallel_for(Index n, int threads, Fn&& fn) {
    const Index workers = std::max<Index>(1, std::min<Index>(threads, n));
    if (workers <= 1) {
        for (Index i = 0; i < n; ++i) fn(i);
        return;
    }
    std::atomic<Index> next{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::mutex error_lock;
    auto work = [&]() {
        try {
            for (Index i = next.fetch_add(1); i < n && !failed.load(); i = next.fetch_add(1))
                fn(i);
        } catch (...) {
            const std::lock_guard<std::mutex> hold(error_lock);
            if (!error) error = std::current_exception();
            failed.store(true);
        }
    };
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(workers - 1));
    try {
        for (Index t = 1; t < workers; ++t) pool.emplace_back(work);
    } catch (...) {  // no thread to be had: the caller's thread does the rest alone
    }
    work();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

}  // namespace pftrack
