// SPDX-License-Identifier: MIT
#pragma once

// Back door of the simulated target (namespace hrg::sim). Tests and the host
// tools use it to configure the board, steer the inputs, inject faults and
// read the true state; the firmware only sees hrg::hal::board() and never
// includes this header.
//
// Lockstep: simulated time advances only inside Adc::read_block, which
// integrates the resonator over one block with the drive the firmware queued
// through Dac::write_block (output one block later, plus latency_samples).
// Within a block, ADC frame n samples the pickoffs at t_n = n / fs and DAC
// frame n is held over [t_n, t_n+1). When the excitation-enable line is low
// the drive amplifiers output zero.

#include <array>
#include <cstdint>
#include <vector>

#include "hal/board.hpp"
#include "sim_target/converters.hpp"
#include "sim_target/noise.hpp"
#include "sim_target/profile.hpp"
#include "sim_target/resonator.hpp"
#include "sim_target/sim_can.hpp"
#include "sim_target/sim_config.hpp"

namespace hrg::sim {

// What really happens, for end-to-end checks.
struct TrueState {
  double t_s = 0.0;
  double pattern_angle_rad = 0.0;  // theta_A, unwrapped since configure()
  double input_angle_rad = 0.0;    // integral of Omega since configure()
  double energy_v2 = 0.0;          // E = a_A^2 + a_B^2
  double a_A_v = 0.0;
  double a_B_v = 0.0;
  double rate_rad_s = 0.0;
  double temp_c = 0.0;
  bool excitation_enabled = false;
  double pump_v = 0.0;  // last pump voltage at the electrode
};

struct SimCounters {
  uint64_t blocks = 0;
  uint64_t adc_clipped = 0;    // ADC samples at a rail
  uint64_t dac_saturated = 0;  // DAC samples at a rail
  uint64_t dac_underruns = 0;  // DAC frames output as zero because no block was queued
};

// Host time spent in each stage of the ADC's read_block (profiling only).
struct SimStageTimes {
  uint64_t dac_ns = 0;        // queued DAC frames -> quantised drive voltages
  uint64_t resonator_ns = 0;  // pickoffs and the full-rate step
  uint64_t noise_ns = 0;      // Gaussian pickoff noise
  uint64_t adc_ns = 0;        // ADC quantisation and faults
  uint64_t block_ns = 0;      // per block: input angle, true wave angle, CAN bus time
  uint64_t samples = 0;
};

class SimTarget {
 public:
  SimTarget();
  SimTarget(const SimTarget&) = delete;
  SimTarget& operator=(const SimTarget&) = delete;

  // Resets everything (resonator state, converters, noise, CAN, time) to `c`.
  void configure(const SimConfig& c);
  const SimConfig& config() const { return config_; }
  hal::Board& board() { return board_; }

  // Inputs and parameters; take effect from the next sample.
  void set_rate_profile(Profile rate_rad_s);
  void set_temperature_profile(Profile temp_c);
  void set_params(const ResonatorParams& p);
  void set_electrodes(const ElectrodeParams& e);
  void set_effects(const Effects& fx);

  // Faults. Channels: ADC 0 = x, 1 = y; DAC 0 = pump, 1 = forcer x, 2 = forcer y.
  void set_adc_stuck(std::size_t channel, bool stuck);          // repeats the last word
  void set_adc_saturated(std::size_t channel, bool saturated);  // at the positive rail
  void set_dac_dead(std::size_t channel, bool dead);            // outputs 0 V
  void noise_burst(double rms_v, double duration_s);  // extra white noise on both ADC channels
  void set_fault_input(bool active) { fault_input_.value = active; }

  TrueState true_state() const;
  SimCounters counters() const { return counters_; }
  // Stage timing of read_block: two host clock reads per stage per chunk of
  // kChunk samples while on, none while off (the default).
  void set_profiling(bool on) { profiling_ = on; }
  // Whether the resonator-and-noise loop and the ADC take their AVX2 forms
  // (on by default where the CPU has AVX2); off, the baseline forms give the
  // same bits.
  void set_wide_kernels(bool on) { wide_ = on && cpu_has_wide(); }
  bool wide_kernels() const { return wide_; }
  const SimStageTimes& stage_times() const { return stage_times_; }
  Resonator& resonator() { return resonator_; }
  SimCan& can() { return can_; }
  double time_s() const;

 private:
  struct SimAdc final : hal::Adc {
    SimTarget* t;
    explicit SimAdc(SimTarget* owner) : t(owner) {}
    hal::ConverterInfo info() const override;
    hal::Status read_block(std::span<hal::q31_t> frames, uint64_t& t_first_ns,
                           uint32_t& clipped) override;
  };
  struct SimDac final : hal::Dac {
    SimTarget* t;
    explicit SimDac(SimTarget* owner) : t(owner) {}
    hal::ConverterInfo info() const override;
    hal::Status write_block(std::span<const hal::q31_t> frames) override;
  };
  struct SimExcitation final : hal::DigitalOut {
    bool value = false;
    hal::Status write(bool active) override {
      value = active;
      return hal::Status::ok;
    }
  };
  struct SimFaultIn final : hal::DigitalIn {
    bool value = false;
    hal::Status read(bool& active) override {
      active = value;
      return hal::Status::ok;
    }
  };
  struct SimClock final : hal::MonotonicClock {
    SimTarget* t;
    explicit SimClock(SimTarget* owner) : t(owner) {}
    uint64_t now_ns() const override;
    hal::Status sleep_until_ns(uint64_t t_ns) override;
  };
  // The temperature sensor of TemperatureSensorConfig: reads the
  // resonator's temperature at the simulated time of the call.
  struct SimTemperature final : hal::TemperatureSensor {
    SimTarget* t;
    explicit SimTemperature(SimTarget* owner) : t(owner) {}
    hal::Status read(double& temp_c) override;
    void reset(uint64_t seed);
    detail::Gaussian noise;
    double lagged_c = 0.0;
    double last_t_s = 0.0;
  };

  // A block is produced in chunks of at most kChunk samples through fixed
  // buffers (nothing is allocated while running).
  static constexpr std::size_t kChunk = 128;

  hal::Status produce_block(std::span<hal::q31_t> frames, uint64_t& t_first_ns, uint32_t& clipped);
  void run_resonator(std::size_t n, double dt);
  template <bool kWide>
  void resonator_loop(std::size_t n, double dt);
  void resonator_wide(std::size_t n, double dt);
  void add_noise(std::size_t n, double dt);
  // Noise on and no burst: the resonator and the noise may share one loop.
  bool plain_noise() const;
  void run_resonator_with_noise(std::size_t n, double dt);
  template <bool kWide>
  void resonator_noise_loop(std::size_t n, double dt);
  void resonator_noise_wide(std::size_t n, double dt);
  uint32_t convert_wide(const double* v, hal::q31_t* out, std::size_t n) const;
  static bool cpu_has_wide();
  uint32_t quantize(std::size_t n, hal::q31_t* out);
  // One ADC conversion with the channel's faults; 1 when it clipped.
  uint32_t quantize_sample(std::size_t ch, double v, hal::q31_t& out) {
    bool clip = false;
    hal::q31_t word = adc_q_.convert(v, clip);
    if (adc_saturated_[ch]) word = adc_q_.convert(1e300, clip);
    if (adc_stuck_[ch]) {
      word = adc_last_[ch];
      clip = false;
    }
    adc_last_[ch] = word;
    out = word;
    return clip ? 1u : 0u;
  }
  // drives_[0..m): the DAC's next m frames through its latency line and quantisers.
  void fill_drives(std::size_t m);
  void fill_drives_loop(std::size_t m);
  void fill_drives_wide(std::size_t m);
  // words_[0..3m) frame by frame through the DAC's latency line (ring),
  // for m below the latency.
  void delay_frames(std::size_t m);
  // For m >= the latency: the line's frames converted into drive_v_'s
  // first frames (returns how many codes were at a rail), and the last
  // `latency` of the m input frames (`queued` of them from input) put in
  // the line.
  uint32_t delayed_out(std::size_t latency);
  void delay_in(const hal::q31_t* input, std::size_t queued, std::size_t m, std::size_t latency);
  uint64_t sample_time_ns(uint64_t index) const;

  SimConfig config_;
  Resonator resonator_;
  AdcQuantizer adc_q_;
  DacQuantizer dac_q_;
  detail::Gaussian noise_;
  SimCan can_;
  SimAdc adc_{this};
  SimDac dac_{this};
  SimExcitation excitation_;
  SimFaultIn fault_input_;
  SimClock clock_{this};
  SimTemperature temperature_{this};
  hal::Board board_;

  uint64_t sample_index_ = 0;
  // Queued DAC frames [dac_head_, end) and the latency line (ring); plain
  // vectors so that configure() can release every allocation.
  std::vector<hal::q31_t> dac_queue_;    // frames, flat
  std::size_t dac_head_ = 0;             // in frames
  std::vector<hal::q31_t> dac_latency_;  // latency_samples frames, flat
  std::size_t latency_pos_ = 0;
  bool dac_written_ = false;
  std::array<bool, 2> adc_stuck_{};
  std::array<bool, 2> adc_saturated_{};
  std::array<hal::q31_t, 2> adc_last_{};
  std::array<bool, hal::kDacChannels> dac_dead_{};
  double burst_rms_v_ = 0.0;
  double burst_left_s_ = 0.0;
  double pattern_angle_rad_ = 0.0;
  double last_theta_rad_ = 0.0;
  double input_angle_rad_ = 0.0;
  ProfileCursor input_rate_;  // config_.rate_rad_s for the input angle's integral, block by block
  double last_pump_v_ = 0.0;
  SimCounters counters_;
  bool profiling_ = false;
  bool wide_ = cpu_has_wide();
  SimStageTimes stage_times_;
  std::array<hal::q31_t, hal::kDacChannels * kChunk> words_{};  // the DAC's frames, flat
  std::array<double, hal::kDacChannels * kChunk> drive_v_{};    // their volts
  std::array<Drive, kChunk> drives_{};
  std::array<double, 2 * kChunk> volts_{};
  std::array<double, 2 * kChunk> noise_buf_{};
};

// The instance behind hrg::hal::board() (configured with SimConfig{} on first
// use); defined in hrg_board_sim, the simulated target chosen at link time.
SimTarget& target();

}  // namespace hrg::sim
