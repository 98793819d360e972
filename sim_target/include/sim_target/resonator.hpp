// SPDX-License-Identifier: MIT
#pragma once

// Full-rate resonator: physics.md eq. 1 in instrument axes, x = C and y = D
// pickoffs in volts of pickoff output, integrated sample by sample.
//
//   x'' + 2nu(1 + dmu c4mu) x' + 2nu dmu s4mu y' - 2 Omega K y' + (w^2 + dw2 c4w) x + dw2 s4w y =
//   F_x y'' + 2nu(1 - dmu c4mu) y' + 2nu dmu s4mu x' + 2 Omega K x' + (w^2 - dw2 c4w) y + dw2 s4w x
//   = F_y F = k_pump (V^2 - <V^2>) G [x, y] + k_s <V^2> G [x, y] + g [V_fx, V_fy] - kappa
//   (x^2+y^2)[x, y]
//
// <V^2> is the DC part of V^2: the mean over the whole samples nearest one
// period of the reference, with the 2w line that leaks through it when the
// period is not a whole number of samples taken out (PumpDcWindow); the
// first term is the parametric pump (2w part of V^2), the second the
// electrostatic spring (k_s = 0 unless Effects::electrostatic_spring is on),
// G the gap pattern (ElectrodeParams). The drive voltages are held over each
// step (zero-order hold, as the DAC outputs them).
//
// Integration (why it is exact to rounding for the linear part): the linear,
// constant-coefficient system at an expansion point (Omega_c, T_c) is advanced
// by its exact propagator Phi = expm(A h), forcer inputs by the exact ZOH
// input matrix. Everything that changes from sample to sample enters through
// exact first-order propagator sensitivities (Van Loan block exponentials):
// the pump coefficient, the temperature's frequency and damping changes, the
// nonlinear terms (evaluated at the step's midpoint), and Omega - Omega_c to
// second order. The expansion point moves when Omega drifts by more than
// 0.05 rad/s or the frequency by more than 1e-3 rad/s, which keeps the
// neglected terms below 1e-15 per step. Cost per sample: one 8x4
// matrix-vector product (the propagator at the present rate, formed only when
// the rate changes, stacked with the pump sensitivity; on a ramp, formed in
// registers inside step_block()'s loop), the
// rate and temperature from profile cursors (no search, no clock), and a
// running <V^2> sum re-added exactly every kHistory steps (its rounding drift
// stays below 2 kHistory eps max(V^2) = 1.2e-11 V^2 at 10 V of pump).
//
// Not thread-safe; copyable.

#include <algorithm>
#include <array>
#include <complex>
#include <cstdint>
#include <cstring>

#include <Eigen/Dense>

#include "sim_target/params.hpp"
#include "sim_target/profile.hpp"
#include "sim_target/pump_dc_window.hpp"

namespace hrg::sim {

// Electrode voltages at the resonator during one step (held; V).
struct Drive {
  double pump_v = 0.0;
  double forcer_x_v = 0.0;
  double forcer_y_v = 0.0;
};

// Pickoff outputs as the ADC sees them (before the ADC's own offset, noise,
// quantisation): mechanical x, y plus the measurement-side effects.
struct PickoffOutput {
  double x_v = 0.0;
  double y_v = 0.0;
};

class Resonator {
 public:
  explicit Resonator(const ResonatorParams& params = {}, const ElectrodeParams& electrodes = {},
                     const Effects& effects = {});

  void set_params(const ResonatorParams& p);
  void set_electrodes(const ElectrodeParams& e);
  void set_effects(const Effects& fx);
  void set_rate_profile(Profile rate_rad_s);     // Omega(t), rad/s
  void set_temperature_profile(Profile temp_c);  // T(t), degC
  // Reference frequency that defines the DC part of V^2 (one period average)
  // and the quarter-period used by the feedthrough phase; default (and after
  // set_params(), until this is called) the resonator's f_hz.
  void set_reference_hz(double f_hz);
  void set_time(double t_s) {
    t0_s_ = t_s;
    steps_ = 0;
    cursor_steps_ = 0;
  }

  // x = Re(X e^{i w t}), y = Re(Y e^{i w t}) with w the present mean frequency,
  // velocities to match: a free state that starts the given envelopes now.
  void set_envelopes(std::complex<double> x_env, std::complex<double> y_env);
  void set_standing_wave(double a_A_v, double theta_rad, double a_B_v = 0.0,
                         double phase_rad = 0.0);
  void set_state(double x_v, double y_v, double vx_v_per_s, double vy_v_per_s);

  // Advances by dt_s (normally 1/fs) with the drive held. Pure physics.
  void step(const Drive& u, double dt_s);
  // n steps under drives[0..n), calling sink(k, measured()) before step k:
  // the same numbers as n calls of measured() and step(). When the rate and
  // the temperature hold one value over the n steps and no amplitude-
  // dependent effect is on, the per-step profile reads, re-expansion checks
  // and coefficient updates are done once for the n steps. While the rate
  // ramps (the temperature held), the rates of a run of steps are read in a
  // pass of their own and each step's propagator is formed in registers
  // (step_varying()). The sink runs inline, so the caller's per-sample work
  // (noise, ADC) overlaps the step's dependency chain.
  //
  // kWide: the held-inputs loop on four rows at a time (step_wide()), for a
  // caller compiled for AVX2 (SimTarget checks the CPU once); the same bits.
  template <bool kWide = false, class Sink>
  [[gnu::always_inline]] void step_block(const Drive* drives, std::size_t n, double dt_s,
                                         Sink&& sink) {
    double rate = 0.0;
    double temp_c = 0.0;
    if (!inputs_held(n, dt_s, rate, temp_c)) {
      step_varying<kWide>(drives, n, dt_s, sink);
      return;
    }
    const HeldCoefficients c = prepare_held(rate, temp_c, dt_s);
    if (kPlainMatchesEigen && c.iso == 0.0 && c.damp == 0.0 && !pickoff_effects_) {
      if constexpr (kWide) {
        step_wide(drives, n, sink);
      } else {
        step_plain(drives, n, sink);
      }
      cursor_steps_ = steps_ - 1;
      return;
    }
    // The state stays in registers: the sink's stores could alias u_, and a
    // store and reload per step would lengthen the step's dependency chain.
    Vec4 u = u_;
    for (std::size_t k = 0; k < n; ++k) {
      if (pickoff_effects_) {
        u_ = u;
        sink(k, measured_with_effects());
      } else {
        sink(k, PickoffOutput{u(0), u(1)});
      }
      Vec4 next = propagate(drives[k], u);
      if (c.iso != 0.0) next.noalias() += psi_iso_ * (c.iso * u);
      if (c.damp != 0.0) next.noalias() += psi_damp_ * (c.damp * u);
      u = next;
      ++steps_;
    }
    u_ = u;
    cursor_steps_ = steps_ - 1;
  }

  // t0 + n dt: counted, not summed, so 6e7 steps of 1e-5 s end at 600 s exactly.
  double time_s() const { return t0_s_ + static_cast<double>(steps_) * step_s_; }
  double x_v() const { return u_(0); }
  double y_v() const { return u_(1); }
  double vx_v_per_s() const { return u_(2); }
  double vy_v_per_s() const { return u_(3); }
  double rate_rad_s() const { return rate_.value(time_s()); }
  double temperature_c() const { return temp_.value(time_s()); }
  double omega_rad_s() const;  // mean angular frequency now (thermal effect included)
  // Analytic envelopes X = x - i x'/w, Y = y - i y'/w (x = Re X at this instant);
  // wave_state() of them gives E, Q, R, S and theta_A of the true wave.
  void envelopes(std::complex<double>& x_env, std::complex<double>& y_env) const;
  PickoffOutput measured() const {
    if (!pickoff_effects_) return {u_(0), u_(1)};  // inline: called once per sample
    return measured_with_effects();
  }
  double last_pump_v() const { return pump_hist_[hist_pos_]; }

 private:
  using Mat4 = Eigen::Matrix<double, 4, 4>;
  using Vec4 = Eigen::Matrix<double, 4, 1>;
  using Mat42 = Eigen::Matrix<double, 4, 2>;

  void expand(double rate_rad_s, double omega_rad_s, double dt_s);
  // The checks and updates step() makes before its product, for a rate and
  // a mean frequency w: re-expansion, the <V^2> window, the rate propagator.
  void prepare_step(double rate_rad_s, double w, double dt_s);
  // The linear part of one step (propagator at the rate, forcers, pump
  // and spring), the <V^2> history advanced by the drive's pump voltage.
  [[gnu::always_inline]] Vec4 propagate(const Drive& drive, const Vec4& u) {
    // Pump history: <V^2>, the DC part of V^2 over one reference period.
    const double v2_dc = push_pump(drive.pump_v);
    // [propagator u; pump sensitivity u] in one 8x4 product.
    const Eigen::Matrix<double, 8, 1> terms = rate_gap_ * u;
    Vec4 next = terms.head<4>();
    next.noalias() += gamma_ * Eigen::Vector2d(drive.forcer_x_v, drive.forcer_y_v);
    const double v2 = drive.pump_v * drive.pump_v;
    const double c_gap = electrodes_.pump_gain_per_s2_v2 * (v2 - v2_dc) + spring_k_ * v2_dc;
    next += c_gap * terms.tail<4>();
    return next;
  }
  // step_block() where the rate or the temperature changes: runs of steps on
  // one piece of the rate profile (a ramp's line up to its corner or the
  // next re-expansion, see ramp_run()) go through step_plain() or
  // step_wide() with each step's propagator formed in registers; the step
  // that ends a run (a corner, a re-expansion) and every case ramp_run()
  // declines go through step().
  template <bool kWide, class Sink>
  [[gnu::always_inline]] void step_varying(const Drive* drives, std::size_t n, double dt_s,
                                           Sink& sink) {
    std::array<double, kRampRun> d_rate;  // each step's rate - rate_c_
    std::size_t k = 0;
    while (k < n) {
      const std::size_t want = std::min(n - k, kRampRun);
      const std::size_t m = ramp_run(want, dt_s, d_rate.data());
      if (m == 0) break;
      const auto shifted =
          [&sink, k ](std::size_t j, const PickoffOutput& p) __attribute__((always_inline)) {
        sink(k + j, p);
      };
      if constexpr (kWide) {
        step_wide<true>(drives + k, m, shifted, d_rate.data());
      } else {
        step_plain<true>(drives + k, m, shifted, d_rate.data());
      }
      cursor_steps_ = steps_ - 1;
      k += m;
      if (m < want) {  // the corner or the re-expansion, as step() takes it
        sink(k, measured());
        step(drives[k], dt_s);
        ++k;
      }
    }
    for (; k < n; ++k) {
      sink(k, measured());
      step(drives[k], dt_s);
    }
  }
  // The longest run of steps, from the present one and at most n, that
  // step_varying() may take without step(): the plain path's conditions (no
  // stiffness, damping, pickoff or amplitude-dependent term), the
  // temperature held over the n steps, the rate on one piece of its profile
  // and within the re-expansion band. Prepares the first step as step()
  // does (re-expands there if due), then reads each step's rate at its
  // midpoint by the cursor's expression and writes rate - rate_c_ to
  // d_rate[0..run). 0 when the path does not apply.
  std::size_t ramp_run(std::size_t n, double dt_s, double* d_rate);
  static constexpr std::size_t kRampRun = 128;  // steps per ramp_run() call
  // step_plain() follows the order of Eigen's packet product on two doubles.
  // Where Eigen does not vectorise doubles in pairs (armhf: no double SIMD),
  // its scalar product sums as a tree, so the general loop is taken instead.
  static constexpr bool kPlainMatchesEigen = Eigen::internal::packet_traits<double>::Vectorizable &&
                                             Eigen::internal::packet_traits<double>::size == 2;
  // step_block's held-inputs loop when no stiffness, damping or pickoff term
  // is on: propagate() written out on pairs of rows, the same operations in
  // the same order (Eigen's sums column by column: ((c0 u0 + c1 u1) + c2 u2)
  // + c3 u3, then the forcers, then the pump and spring term), so the same
  // bits, with the state in registers from one step to the next.
  // kRamp: the rate changes from step to step; step k's propagator is
  // Phi + dO Psi1 + dO^2 Psi2 with dO = d_rate[k], formed here per element
  // in prepare_step()'s order ((Phi + dO Psi1) + dO^2 Psi2), the same bits.
  template <bool kRamp = false, class Sink>
  [[gnu::always_inline]] void step_plain(const Drive* drives, std::size_t n, Sink& sink,
                                         const double* d_rate = nullptr) {
    using v2d = double __attribute__((vector_size(16)));
    const auto pair = [](const double* p) {
      v2d v;
      std::memcpy(&v, p, sizeof v);
      return v;
    };
    const auto splat = [](double x) { return v2d{x, x}; };
    const double* r = rate_gap_.data();  // 8x4, column-major
    const double* g = gamma_.data();     // 4x2, column-major
    const double* p0 = phi_.data();      // 4x4, column-major
    const double* p1 = psi_rate1_.data();
    const double* p2 = psi_rate2_.data();
    const double k_pump = electrodes_.pump_gain_per_s2_v2;
    const double k_spring = spring_k_;
    v2d pos = {u_(0), u_(1)};  // x, y
    v2d vel = {u_(2), u_(3)};  // x', y'
    for (std::size_t k = 0; k < n; ++k) {
      sink(k, PickoffOutput{pos[0], pos[1]});
      const Drive d = drives[k];
      const double v2_dc = push_pump(d.pump_v);
      const double v2 = d.pump_v * d.pump_v;
      const v2d c_gap = splat(k_pump * (v2 - v2_dc) + k_spring * v2_dc);
      const v2d u0 = splat(pos[0]);
      const v2d u1 = splat(pos[1]);
      const v2d u2 = splat(vel[0]);
      const v2d u3 = splat(vel[1]);
      // Rows (i, i + 1) of column j of Phi_rate (i < 4) or Psi_gap.
      v2d dv{};
      v2d dd{};
      if constexpr (kRamp) {
        dv = splat(d_rate[k]);
        dd = splat(d_rate[k] * d_rate[k]);
      }
      const auto col = [&](std::size_t j, std::size_t i) {
        if constexpr (kRamp) {
          if (i < 4)
            return (pair(p0 + 4 * j + i) + dv * pair(p1 + 4 * j + i)) + dd * pair(p2 + 4 * j + i);
        }
        return pair(r + 8 * j + i);
      };
      // Rows (i, i + 1) of [Phi_rate; Psi_gap] u, column by column.
      const auto rows = [&](std::size_t i) {
        return ((col(0, i) * u0 + col(1, i) * u1) + col(2, i) * u2) + col(3, i) * u3;
      };
      const v2d fx = splat(d.forcer_x_v);
      const v2d fy = splat(d.forcer_y_v);
      pos = (rows(0) + (pair(g) * fx + pair(g + 4) * fy)) + c_gap * rows(4);
      vel = (rows(2) + (pair(g + 2) * fx + pair(g + 6) * fy)) + c_gap * rows(6);
    }
    steps_ += n;
    u_ << pos[0], pos[1], vel[0], vel[1];
  }
  // step_plain() on four rows at a time: rows 0-3 of [Phi_rate; Psi_gap]
  // (x, y, x', y' at once) and rows 4-7, each column's product and sum in
  // the same order per row as step_plain() and Eigen, so the same bits; the
  // twelve columns stay in registers (AVX2 has sixteen of four doubles). No
  // fused multiply-add: AVX2 alone does not enable FMA, so the compiler
  // cannot contract a product and a sum into one rounding. kRamp: as in
  // step_plain(), rows 0-3 formed per step from d_rate[k].
  template <bool kRamp = false, class Sink>
  [[gnu::always_inline]] void step_wide(const Drive* drives, std::size_t n, Sink& sink,
                                        const double* d_rate = nullptr) {
    using v4d = double __attribute__((vector_size(32)));
    const double* r = rate_gap_.data();  // 8x4, column-major
    const double* g = gamma_.data();     // 4x2, column-major
    v4d phi[4];
    v4d gap[4];
    v4d phi0[4];  // Phi, Psi1, Psi2 (kRamp)
    v4d psi1[4];
    v4d psi2[4];
    for (std::size_t j = 0; j < 4; ++j) {
      std::memcpy(&phi[j], r + 8 * j, sizeof(v4d));
      std::memcpy(&gap[j], r + 8 * j + 4, sizeof(v4d));
      if constexpr (kRamp) {
        std::memcpy(&phi0[j], phi_.data() + 4 * j, sizeof(v4d));
        std::memcpy(&psi1[j], psi_rate1_.data() + 4 * j, sizeof(v4d));
        std::memcpy(&psi2[j], psi_rate2_.data() + 4 * j, sizeof(v4d));
      }
    }
    v4d gx;
    v4d gy;
    std::memcpy(&gx, g, sizeof gx);
    std::memcpy(&gy, g + 4, sizeof gy);
    const double k_pump = electrodes_.pump_gain_per_s2_v2;
    const double k_spring = spring_k_;
    v4d u = {u_(0), u_(1), u_(2), u_(3)};
    PumpRing pump_ring(*this);
    for (std::size_t k = 0; k < n; ++k) {
      sink(k, PickoffOutput{u[0], u[1]});
      const Drive d = drives[k];
      const double v2_dc = pump_ring.push(d.pump_v);
      const double v2 = d.pump_v * d.pump_v;
      const double c_gap = k_pump * (v2 - v2_dc) + k_spring * v2_dc;
      if constexpr (kRamp) {
        const double dr = d_rate[k];
        const double dr2 = dr * dr;
        const v4d dv = {dr, dr, dr, dr};
        const v4d dd = {dr2, dr2, dr2, dr2};
        for (std::size_t j = 0; j < 4; ++j)
          phi[j] = (phi0[j] + dv * psi1[j]) + dd * psi2[j];
      }
      const v4d u0 = {u[0], u[0], u[0], u[0]};
      const v4d u1 = {u[1], u[1], u[1], u[1]};
      const v4d u2 = {u[2], u[2], u[2], u[2]};
      const v4d u3 = {u[3], u[3], u[3], u[3]};
      const v4d rate = ((phi[0] * u0 + phi[1] * u1) + phi[2] * u2) + phi[3] * u3;
      const v4d pump = ((gap[0] * u0 + gap[1] * u1) + gap[2] * u2) + gap[3] * u3;
      const v4d fx = {d.forcer_x_v, d.forcer_x_v, d.forcer_x_v, d.forcer_x_v};
      const v4d fy = {d.forcer_y_v, d.forcer_y_v, d.forcer_y_v, d.forcer_y_v};
      const v4d cg = {c_gap, c_gap, c_gap, c_gap};
      u = (rate + (gx * fx + gy * fy)) + cg * pump;
    }
    pump_ring.store();
    steps_ += n;
    u_ << u[0], u[1], u[2], u[3];
  }
  // Whether step_block may take its held-inputs path; the rate and the
  // temperature it holds when so.
  bool inputs_held(std::size_t n, double dt_s, double& rate_rad_s, double& temp_c);
  // step()'s per-step coefficients for held inputs (no energy term is on).
  struct HeldCoefficients {
    double iso;   // stiffness change c I: w^2 - w_c^2
    double damp;  // damping scale - 1
  };
  HeldCoefficients prepare_held(double rate_rad_s, double temp_c, double dt_s);
  // The pump delay_samples ago, interpolated as a sinusoid of step_rad per
  // sample (the reference's): the history sample `whole` back and the one before.
  struct PumpLag {
    int whole = 0;
    double w_whole = 1.0;
    double w_next = 0.0;
  };
  static PumpLag pump_lag(double delay_samples, double step_rad);
  double pump_delayed(const PumpLag& lag) const;
  // The pump history's position and running sum in locals over a loop of
  // steps (registers: the caller's stores could alias the members), the
  // same operations as push_pump(); back into the members by store().
  struct PumpRing {
    explicit PumpRing(Resonator& r)
        : res(r),
          hist(r.pump_hist_.data()),
          sq(r.pump_sq_hist_.data()),
          pos(r.hist_pos_),
          window(r.dc_window_),
          sum(r.pump_sq_sum_),
          valid(r.pump_sum_valid_) {}
    [[gnu::always_inline]] double push(double pump_v) {
      constexpr int kMask = kHistory - 1;
      pos = (pos + 1) & kMask;
      const double leaving = sq[(pos - window.length) & kMask];
      hist[pos] = pump_v;
      sq[pos] = pump_v * pump_v;
      if (pos == 0 || !valid) [[unlikely]] {
        store();
        res.readd_pump_squares();
        sum = res.pump_sq_sum_;
        valid = true;
      } else {
        sum += sq[pos] - leaving;
      }
      return window.dc(sum, sq[pos], sq[(pos - window.lag) & kMask]);
    }
    void store() const {
      res.hist_pos_ = pos;
      res.pump_sq_sum_ = sum;
      res.pump_sum_valid_ = valid;
    }
    Resonator& res;
    double* hist;
    double* sq;
    int pos;
    PumpDcWindow window;
    double sum;
    bool valid;
  };
  double push_pump(double pump_v) {      // records the held pump voltage, returns <V^2>
    constexpr int kMask = kHistory - 1;  // kHistory is a power of two
    hist_pos_ = (hist_pos_ + 1) & kMask;
    const double leaving = pump_sq_hist_[(hist_pos_ - dc_window_.length) & kMask];
    pump_hist_[hist_pos_] = pump_v;
    pump_sq_hist_[hist_pos_] = pump_v * pump_v;
    if (hist_pos_ == 0 || !pump_sum_valid_) {
      readd_pump_squares();
    } else {
      pump_sq_sum_ += pump_sq_hist_[hist_pos_] - leaving;
    }
    return dc_window_.dc(pump_sq_sum_, pump_sq_hist_[hist_pos_],
                         pump_sq_hist_[(hist_pos_ - dc_window_.lag) & kMask]);
  }
  void readd_pump_squares();
  PickoffOutput measured_with_effects() const;
  static bool any_pickoff_effect(const Effects& fx) {
    return fx.pickoff_misalignment.enabled || fx.pickoff_gain_mismatch.enabled ||
           fx.pickoff_phase_mismatch.enabled || fx.drive_feedthrough.enabled;
  }

  ResonatorParams params_;
  ElectrodeParams electrodes_;
  Effects effects_;
  bool pickoff_effects_ = false;  // any effect on the measured side
  Profile rate_;
  Profile temp_;
  ProfileCursor rate_at_;  // rate_ and temp_ at step midpoints, sample by sample
  ProfileCursor temp_at_;
  double f_ref_hz_;
  bool f_ref_set_ = false;  // set_reference_hz() called: no longer params_.f_hz
  double t0_s_ = 0.0;
  uint64_t steps_ = 0;
  uint64_t cursor_steps_ = 0;  // steps_ at the cursors' last sample
  double step_s_ = 0.0;
  Vec4 u_ = Vec4::Zero();

  // Expansion point and its propagators.
  bool expanded_ = false;
  double rate_c_ = 0.0;
  double omega_c_ = 0.0;
  double dt_c_ = 0.0;
  Mat4 phi_;                    // expm(A h)
  Mat4 phi_half_;               // expm(A h/2), midpoint prediction of the nonlinear terms
  Mat42 gamma_;                 // ZOH input matrix of the forcers (gain included)
  Mat4 psi_rate1_, psi_rate2_;  // d Phi / d Omega and the second-order term
  Mat4 psi_gap_;                // sensitivity to a stiffness -c G (pump, spring): force +c G u
  Mat4 psi_iso_;                // sensitivity to a stiffness +c I (frequency change, Duffing)
  Mat4 psi_damp_;               // sensitivity to scaling the damping matrix by (1 + c)
  // [Phi + dO Psi1 + dO^2 Psi2; psi_gap_] with dO = rate_prop_d_: one product per step.
  Eigen::Matrix<double, 8, 4> rate_gap_;
  double rate_prop_d_ = 0.0;
  bool rate_prop_valid_ = false;
  double spring_k_ = 0.0;  // DC-pump stiffness per V^2 of <V^2> (0 when off)

  // Pump history for <V^2> and the feedthrough phase.
  static constexpr int kHistory = 256;
  static_assert((kHistory & (kHistory - 1)) == 0, "the ring index is masked");
  std::array<double, kHistory> pump_hist_{};
  std::array<double, kHistory> pump_sq_hist_{};
  int hist_pos_ = 0;
  PumpDcWindow dc_window_;    // set from f_ref_hz_ and the step at the first step
  double pump_sq_sum_ = 0.0;  // running sum of the last dc_window_.length squares
  bool pump_sum_valid_ = false;
  // The step the window was set for; none yet, so the first step sets it
  // (a window fixed at construction would hold 20 samples, one period only
  // of a 5 kHz reference at 100 kHz, whatever the resonator's frequency).
  double dt_last_ = -1.0;
  PumpLag quarter_lag_{};  // a quarter of the reference's period, at dt_last_
};

}  // namespace hrg::sim
