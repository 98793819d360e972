// SPDX-License-Identifier: MIT
// The batch runner: every index runs once, results come back by index
// whatever the thread count, and a job's exception reaches the caller.
#include <atomic>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "batch/batch.hpp"

#include "support/cpputest.hpp"

namespace {
// A job whose cost varies with its index, so threads finish out of order.
double slow_sum(std::size_t i) {
  double s = 0.0;
  for (std::size_t k = 0; k < 20'000 * (1 + i % 7); ++k)
    s += static_cast<double>(k % (i + 3)) * 1e-3;
  return s;
}
}  // namespace

TEST_GROUP_WITHOUT_LEAK_CHECK(Batch);

TEST(Batch, ResultsAreByIndexAndIdenticalForAnyThreadCount) {
  const auto one = hrg::batch::run_indexed(57, 1, slow_sum);
  for (unsigned jobs : {2u, 3u, 8u}) {
    const auto many = hrg::batch::run_indexed(57, jobs, slow_sum);
    CHECK_EQUAL(one.size(), many.size());
    for (std::size_t i = 0; i < one.size(); ++i)
      CHECK_EQUAL(one[i], many[i]);  // bit for bit
  }
  CHECK_EQUAL(slow_sum(5), one[5]);
}

TEST(Batch, EveryIndexRunsExactlyOnce) {
  std::vector<std::atomic<int>> runs(100);
  hrg::batch::run_indexed(runs.size(), 4, [&](std::size_t i) {
    runs[i].fetch_add(1);
    return 0;
  });
  for (const auto& r : runs)
    CHECK_EQUAL(1, r.load());
}

TEST(Batch, TheLowestFailingIndexIsRethrownAfterAllFinish) {
  std::atomic<int> done{0};
  try {
    hrg::batch::run_indexed(40, 3, [&](std::size_t i) -> int {
      ++done;
      if (i == 7 || i == 30) throw std::runtime_error("job " + std::to_string(i));
      return 0;
    });
    FAIL("no exception");
  } catch (const std::runtime_error& e) {
    STRCMP_EQUAL("job 7", e.what());
  }
  CHECK_EQUAL(40, done.load());
}

TEST(Batch, JobsOptionIsAPositiveCountOrZeroForAllCores) {
  unsigned j = 99;
  CHECK(hrg::batch::parse_jobs("3", j));
  CHECK_EQUAL(3u, j);
  CHECK(hrg::batch::parse_jobs("0", j));
  CHECK_EQUAL(hrg::batch::all_cores(), j);
  j = 5;
  CHECK_FALSE(hrg::batch::parse_jobs("-1", j));
  CHECK_FALSE(hrg::batch::parse_jobs("two", j));
  CHECK_FALSE(hrg::batch::parse_jobs("", j));
  CHECK_EQUAL(5u, j);
}
