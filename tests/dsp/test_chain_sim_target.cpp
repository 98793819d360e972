// SPDX-License-Identifier: MIT
// The chain on the simulated target's own converters (sim::SimTarget through
// hal::Board: 24-bit ADC at 2.5 V, 16-bit DAC at 10 V, one block of double
// buffering), as the firmware runs it: checks that the chain's default DAC
// lead matches the converters, so the pump works at its best phase.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "dsp/chain.hpp"
#include "sim_target/control.hpp"

#include "support/cpputest.hpp"

using namespace hrg;

TEST_GROUP(ChainOnSimTarget){};

TEST(ChainOnSimTarget, HoldsTheWaveWithThePumpAtItsBestPhase) {
  for (double theta : {0.0, 0.35}) {
    // GIVEN the simulated board ringing at 1 V and a chain set up from its
    // converter descriptions
    sim::SimConfig sc;
    sc.initial.amplitude_v = 1.0;
    sc.initial.theta_rad = theta;
    sim::SimTarget target;
    target.configure(sc);
    hal::Board& b = target.board();
    dsp::ChainConfig cfg;
    cfg.sample_rate_hz = b.adc.info().sample_rate_hz;
    cfg.block_frames = b.adc.info().block_frames;
    cfg.adc_full_scale_v = b.adc.info().full_scale_v;
    cfg.dac_full_scale_v = b.dac.info().full_scale_v;
    dsp::Chain<dsp::q31_t> chain(cfg);
    chain.set_excitation(true);
    CHECK(b.excitation_enable.write(true) == hal::Status::ok);
    std::vector<hal::q31_t> adc(2 * cfg.block_frames), dac(3 * cfg.block_frames);
    // WHEN the chain runs for 4 s, block by block
    double worst_a = 0.0, worst_q = 0.0;
    for (int k = 0; k < 4000; ++k) {
      uint64_t t_ns = 0;
      uint32_t clipped = 0;
      CHECK(b.adc.read_block(adc, t_ns, clipped) == hal::Status::ok);
      CHECK(chain.process(adc, dac));
      CHECK(b.dac.write_block(dac) == hal::Status::ok);
      if (k >= 2000) {
        worst_a = std::fmax(worst_a, std::fabs(chain.outputs().wave.a_A_v - 1.0));
        worst_q = std::fmax(worst_q, std::fabs(target.true_state().a_B_v));
      }
    }
    // THEN amplitude and quadrature are held and V0 is the parametric
    // threshold of wave A, raised only by the zero-order hold at 2f: a wrong
    // DAC lead (phase) would need more pump (1 / cos of twice the error)
    const auto& rp = sc.resonator;
    const double nu_a = rp.nu_per_s() * (1.0 + rp.dmu * std::cos(4.0 * (theta - rp.th_mu_rad)));
    const double x = 2.0 * std::numbers::pi * rp.f_hz / cfg.sample_rate_hz;
    const double v0 =
        sc.electrodes.threshold_v(rp.omega_rad_s(), nu_a) / std::sqrt(std::sin(x) / x);
    std::printf(
        "\n  sim target, theta %.2f: V0 %.5f V (threshold with hold %.5f), |a_A - 1| %.1e, "
        "|a_B| %.1e V\n",
        theta, chain.outputs().pump_v, v0, worst_a, worst_q);
    DOUBLES_EQUAL(v0, chain.outputs().pump_v, 2e-3 * v0);
    CHECK(worst_a < 1e-4);
    CHECK(worst_q < 1e-4);
    CHECK(target.counters().dac_underruns == 0);
  }
}
