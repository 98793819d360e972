// SPDX-License-Identifier: MIT
// Excitation segments whose pump_v jitters from row to row by more than 0.3
// of its level are left out of the excitation observations (dataset.cpp,
// pump_jitter): an amplitude loop oscillating faster than the rows makes the
// rows alias the pump. A pump the loop holds (a few percent) keeps them.
#include <cmath>
#include <string>
#include <vector>

#include "../../tools/audit/src/campaign.hpp"
#include "../../tools/audit/src/dataset.hpp"
#include "recording/recording.hpp"

#include "support/cpputest.hpp"

namespace bench = hrg::audit::bench;
namespace detail = hrg::audit::detail;
namespace recording = hrg::recording;

namespace {

// The telemetry design of `hrg audit-bench --seed 2026` (design 1), null.
recording::Recording null_recording() {
  auto s = bench::random_scenario(bench::Design::telemetry, 360.0, 2026ULL * 100003ULL + 1ULL);
  s.temp_cycles = true;
  return bench::simulate(s);
}

// The recording with pump_v over rows [r0, r1] alternating by +-rel of its
// value from row to row (second differences 4 rel V: a jitter of 4 rel /
// sqrt(6) of the level).
recording::Recording with_jitter(const recording::Recording& rec, std::size_t r0, std::size_t r1,
                                 double rel) {
  recording::Recording out(rec.column_names(), rec.f_ref_hz(), rec.angular_gain());
  for (const auto& [k, v] : rec.metadata())
    out.set_metadata(k, v);
  std::size_t pump = 0;
  while (rec.column_names()[pump] != "pump_v")
    ++pump;
  std::vector<double> row(rec.column_names().size());
  for (std::size_t i = 0; i < rec.rows(); ++i) {
    for (std::size_t c = 0; c < row.size(); ++c)
      row[c] = rec.column(rec.column_names()[c])[i];
    if (i >= r0 && i <= r1) row[pump] *= 1.0 + (i % 2 == 0 ? rel : -rel);
    out.append_row(row);
  }
  return out;
}

}  // namespace

TEST_GROUP(AuditPumpJitter){};

TEST(AuditPumpJitter, AnExcitationSegmentWhosePumpAlternatesFromRowToRowIsLeftOut) {
  // GIVEN the null, whose excitation segments all have a held pump
  const auto rec = null_recording();
  CHECK_TRUE(rec.has_column("pump_v"));
  const auto d0 = detail::build_dataset(rec, 12000);
  LONGS_EQUAL(0, d0.forced_jittery);
  CHECK_TRUE(d0.forced.size() >= 40);
  const auto& f = d0.forced[d0.forced.size() / 2];
  // WHEN the pump of one of them alternates by +-0.2 of its value (jitter 0.33)
  const auto d1 = detail::build_dataset(with_jitter(rec, f.first_row, f.last_row, 0.2), 12000);
  // THEN that segment alone is left out, and a note says why
  LONGS_EQUAL(1, d1.forced_jittery);
  LONGS_EQUAL(d0.forced.size() - 1, d1.forced.size());
  bool noted = false;
  for (const auto& n : d1.notes)
    noted = noted || n.find("pump_v jitters") != std::string::npos;
  CHECK_TRUE(noted);
  // AND by +-0.15 (jitter 0.24, below 0.3) it is kept
  const auto d2 = detail::build_dataset(with_jitter(rec, f.first_row, f.last_row, 0.15), 12000);
  LONGS_EQUAL(0, d2.forced_jittery);
  LONGS_EQUAL(d0.forced.size(), d2.forced.size());
}
