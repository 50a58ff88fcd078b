// Runs fn(0) .. fn(n - 1) on up to min(n, hardware threads) threads, the caller's among them; each
// index once, taken in order from a shared counter. The first exception is rethrown after all
// threads have stopped (the others stop taking indices).
#pragma once

#include <cstddef>
#include <functional>

namespace fv::util {

void ParallelFor(size_t n, const std::function<void(size_t)>& fn);

}  // namespace fv::util
