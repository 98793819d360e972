// SPDX-License-Identifier: MIT
// The telemetry's rows against the fixed reference: whatever the NCO's phase
// did, the envelope a reader rebuilds from (f_ref, t_s) on the bus gives the
// pickoff signal the chain measured, at the row's time.
#include <cmath>
#include <complex>
#include <numbers>

#include "firmware/can/envelope_reference.hpp"
#include "firmware/can/messages.hpp"

#include "support/cpputest.hpp"

using namespace hrg::fw::can;

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
using cd = std::complex<double>;

// The NCO's phase beyond the fixed reference: a PLL pulling (linear between
// block ends, as the chain's NCO runs at one frequency per block).
double wander_rad(int block) { return 0.4 * std::sin(0.05 * block) + 1e-3 * block; }

}  // namespace

TEST_GROUP(EnvelopeReference){};

TEST(EnvelopeReference, AReaderRebuildsTheMeasuredSignalFromTheReferenceAndTheRowTime) {
  EnvelopeReferenceConfig cfg;
  cfg.f_ref_hz = 5000.0000031;  // off the bus's 10 uHz grid: the grid's value is used
  cfg.block_period_s = 1e-3;
  cfg.centre_blocks = 2;
  EnvelopeReference ref(cfg);
  DOUBLES_EQUAL(5000.0, ref.f_ref_hz(), 1e-9);
  const double f = ref.f_ref_hz();
  // A wave ringing 0.13 Hz above the reference, amplitude 1.2 V (x) and a
  // quadrature on y; block ends off the 0.1 ms grid of HRG_ROW.t_s.
  const auto t_end = [](int k) { return 12.0 + 1e-3 * k + 3.7e-5; };
  const auto z_true = [](double t) {
    return std::pair{cd(1.2, -0.1) * std::exp(cd(0, kTwoPi * 0.13 * t)),
                     cd(0.02, 0.3) * std::exp(cd(0, kTwoPi * 0.13 * t))};
  };
  double worst = 0;
  for (int k = 0; k < 400; ++k) {
    const double nco_cycles = f * t_end(k) + wander_rad(k) / kTwoPi;
    const double frac = nco_cycles - std::floor(nco_cycles);
    ref.after_block(t_end(k), static_cast<uint32_t>(std::llround(frac * 0x1p32) & 0xFFFFFFFFll),
                    true);
    CHECK_EQUAL(k >= 3, ref.ready());
    if (!ref.ready()) continue;
    // The chain's quadratures: the envelope at the window's centre (2.5
    // blocks back), against the NCO there.
    const double t_c = t_end(k) - 2.5e-3;
    const double w_c = 0.5 * (wander_rad(k - 2) + wander_rad(k - 3));
    const auto [zx, zy] = z_true(t_c);
    const cd nx = zx * std::exp(cd(0, -w_c));
    const cd ny = zy * std::exp(cd(0, -w_c));
    const EnvelopeRow row = ref.row(nx.real(), -nx.imag(), ny.real(), -ny.imag());
    // THEN t_s is on the bus's grid, within half a step of the centre, and
    // x(t) = Re((cx - i sx) e^(i 2 pi f_ref t)) rebuilt at t_s is the signal
    // at the centre (rebuilt with the reference turned by the row time error).
    DOUBLES_EQUAL(std::round(row.t_s * 1e4) * 1e-4, row.t_s, 1e-9);
    DOUBLES_EQUAL(t_c, row.t_s, 0.5e-4 + 1e-9);
    const cd rx(row.cx_v, -row.sx_v), ry(row.cy_v, -row.sy_v);
    const cd e_read = std::exp(cd(0, kTwoPi * std::fmod(f * row.t_s, 1.0)));
    const cd e_true = std::exp(cd(0, kTwoPi * std::fmod(f * t_c, 1.0)));
    worst = std::max(worst, std::abs(rx * e_read - zx * e_true));
    worst = std::max(worst, std::abs(ry * e_read - zy * e_true));
  }
  // Exact to the NCO word's 2^-32 cycle and the arithmetic (the NCO's
  // wander of up to 0.4 rad would leave 0.5 V).
  CHECK_TEXT(worst < 1e-8, std::to_string(worst).c_str());
}

TEST(EnvelopeReference, ARowIsDrivenUntilTheLastDriveLeavesTheDemodulatorsWindow) {
  EnvelopeReferenceConfig cfg;
  cfg.drive_free_blocks = 7;
  EnvelopeReference ref(cfg);
  // Drive-free from the start (nothing was driven yet).
  ref.after_block(1e-3, 0, false);
  CHECK_FALSE(ref.row(0, 0, 0, 0).exc);
  for (int k = 2; k < 50; ++k)
    ref.after_block(1e-3 * k, 0, true);
  CHECK(ref.row(0, 0, 0, 0).exc);
  // The excitation goes off: six blocks later the window still holds driven
  // samples, the seventh is free.
  for (int k = 50; k < 56; ++k) {
    ref.after_block(1e-3 * k, 0, false);
    CHECK(ref.row(0, 0, 0, 0).exc);
  }
  ref.after_block(56e-3, 0, false);
  CHECK_FALSE(ref.row(0, 0, 0, 0).exc);
}
