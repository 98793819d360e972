// SPDX-License-Identifier: MIT
#pragma once

// Batches of independent jobs across cores: every study of the project (the
// audit benchmark's designs, the calibration table's rows, Monte Carlo over
// resonators and electronics) is a list of runs that share nothing.
//
// run_indexed(n, jobs, f) calls f(i) once for every i in [0, n) on `jobs`
// threads and returns the results by index, so what a caller prints from them
// is in the same order and has the same content for any thread count (as long
// as f(i) depends on i alone). Threads take the next index from one atomic
// counter; there is no other scheduling. An exception thrown by f(i) is
// rethrown after every thread has finished (the lowest such index wins).
// With jobs <= 1, f runs on the calling thread.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <string>
#include <thread>
#include <vector>

namespace hrg::batch {

// The machine's cores (std::thread::hardware_concurrency), at least 1.
unsigned all_cores();

// Parses a --jobs value: a positive integer, or 0 for all cores. Returns false
// (and leaves `jobs` alone) for anything else.
bool parse_jobs(const std::string& text, unsigned& jobs);

template <class F>
auto run_indexed(std::size_t n, unsigned jobs, F&& f) -> std::vector<decltype(f(std::size_t{}))> {
  using R = decltype(f(std::size_t{}));
  std::vector<R> results(n);
  std::vector<std::exception_ptr> errors(n);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next.fetch_add(1); i < n; i = next.fetch_add(1)) {
      try {
        results[i] = f(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  const std::size_t threads = std::min<std::size_t>(jobs == 0 ? all_cores() : jobs, n);
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::jthread> pool;
    pool.reserve(threads);
    for (std::size_t t = 0; t < threads; ++t)
      pool.emplace_back(worker);
  }  // the jthreads join here
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return results;
}

}  // namespace hrg::batch
