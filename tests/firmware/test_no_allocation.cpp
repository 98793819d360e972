// SPDX-License-Identifier: MIT
// "Nothing allocated after init": the firmware with the real DSP chain and the
// real estimator runs its frames without a single operator new (and without
// an Eigen heap allocation).
#include <Eigen/Core>

#include <memory>
#include <vector>

#include "fakes/counting_allocator.hpp"
#include "fakes/fake_board.hpp"
#include "fakes/fake_chain.hpp"
#include "firmware/dsp_chain_port.hpp"
#include "firmware/estimator_port.hpp"
#include "firmware/gyro.hpp"

#include "support/cpputest.hpp"
#include "support/short_window_config.hpp"

using hrg::fw::Gyro;
using hrg::fw::Mode;
using hrg::fw::Pacing;

TEST_GROUP(CountingNewAllocator){};

TEST(CountingNewAllocator, CountsEveryOperatorNewWhileInstalled) {
  hrg::fakes::CountingNewAllocator counter;
  counter.install();
  auto v = std::make_unique<std::vector<int>>(10);
  counter.uninstall();
  LONGS_EQUAL(2, counter.count());  // the vector object and its storage
  auto w = std::make_unique<int>(1);
  LONGS_EQUAL(2, counter.count());
}

TEST_GROUP(NoAllocation) {
  hrg::fakes::FakeBoard b;
  hrg::fakes::FakeClock timer;
  hrg::fakes::CountingNewAllocator counter;
};

TEST(NoAllocation, TheGyroWithTheDspChainAllocatesNothingPerFrame) {
  hrg::dsp::ChainConfig cc;
  cc.adc_full_scale_v = 2.5;
  hrg::fw::DspChainPort chain(cc);
  hrg::fakes::FakeResonatorIdentifier ident;
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, hrg::test::short_window_config());
  counter.install();
  Eigen::internal::set_is_malloc_allowed(false);
  for (int i = 0; i < 3000; ++i)
    g.run_frame();
  Eigen::internal::set_is_malloc_allowed(true);
  counter.uninstall();
  LONGS_EQUAL(3000, chain.chain().outputs().blocks);
  LONGS_EQUAL(0, counter.count());
}

TEST(NoAllocation, TheGyroWithTheEstimatorAllocatesNothingThroughWindowsAndSolves) {
  hrg::fakes::FakeChain chain;
  chain.theta_rate_rad_per_block = 2e-4;  // the pattern turns: windows land in many bins
  chain.decay_per_block = 3e-6;           // nu = 3e-3 1/s at 1 kHz
  hrg::est::Estimator::Config ec;
  hrg::fw::EstimatorPort ident(ec);
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, hrg::test::short_window_config());
  counter.install();
  Eigen::internal::set_is_malloc_allowed(false);
  for (int i = 0; i < 6000; ++i)
    g.run_frame();
  Eigen::internal::set_is_malloc_allowed(true);
  counter.uninstall();
  CHECK(ident.windows_accepted() >= 10);
  CHECK(g.status().mode == Mode::operate || g.status().mode == Mode::free_decay ||
        g.status().mode == Mode::recover);
  LONGS_EQUAL(0, counter.count());
}

TEST(NoAllocation, TheDampingModelCheckAndTheSeedModelBesideItAllocateNothing) {
  hrg::fakes::FakeChain chain;
  chain.theta_rate_rad_per_block = 2e-4;
  chain.decay_per_block = 3e-6;
  hrg::est::Estimator::Config ec;
  hrg::fw::EstimatorPort ident(ec);
  // A damping part (nonlinear damping: the scale follows the wave's energy
  // without a temperature sensor) puts the check and the seed's model to work.
  hrg::fw::Calibration cal{};
  cal.nonlinear_damping_per_v2 = 0.05;
  ident.set_resonator_model(cal);
  CHECK(ident.seed_model_kept());
  Gyro g(b.board, chain, ident, timer, Pacing::lockstep, hrg::test::short_window_config());
  counter.install();
  Eigen::internal::set_is_malloc_allowed(false);
  for (int i = 0; i < 6000; ++i)
    g.run_frame();
  ident.fall_back_to_seed_model();
  for (int i = 0; i < 1000; ++i)
    g.run_frame();
  Eigen::internal::set_is_malloc_allowed(true);
  counter.uninstall();
  CHECK(ident.windows_accepted() >= 10);
  CHECK(ident.damping_model_check().windows >= 10);
  CHECK(!ident.seed_model_kept());
  LONGS_EQUAL(0, counter.count());
}
