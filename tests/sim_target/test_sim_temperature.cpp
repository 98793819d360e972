// SPDX-License-Identifier: MIT
// The simulated board's temperature sensor (hal::TemperatureSensor): the
// resonator's temperature quantised to the sensor's resolution, and, when
// configured, lagged (first order) and noisy.
#include <cmath>
#include <vector>

#include "hal/board.hpp"
#include "sim_target/control.hpp"

#include "support/cpputest.hpp"

using namespace hrg;
using namespace hrg::sim;

namespace {

// Advances the simulated time by one ADC block (1 ms at the defaults).
void one_block(SimTarget& t) {
  std::vector<hal::q31_t> v(t.board().adc.info().block_frames * hal::kAdcChannels);
  uint64_t t_ns = 0;
  uint32_t clipped = 0;
  CHECK(t.board().adc.read_block(v, t_ns, clipped) == hal::Status::ok);
}

}  // namespace

TEST_GROUP(SimTemperature){};

TEST(SimTemperature, ReadsTheResonatorTemperatureQuantisedToTheSensorResolution) {
  SimTarget t;
  SimConfig c;
  c.temp_c = Profile::constant(25.3004);
  t.configure(c);
  double v = 0.0;
  // At the default millidegree: 25300.4 mdegC -> 25300 mdegC
  CHECK(t.board().temperature.read(v) == hal::Status::ok);
  DOUBLES_EQUAL(25.3, v, 1e-12);
  // A 16-bit part at 2^-7 degC: 3238.45 LSB -> 3238 LSB = 25.296875 degC
  c.temperature_sensor.lsb_c = 0.0078125;
  t.configure(c);
  CHECK(t.board().temperature.read(v) == hal::Status::ok);
  DOUBLES_EQUAL(25.296875, v, 0.0);
}

TEST(SimTemperature, ABoardWithoutTheSensorReadsClosed) {
  SimTarget t;
  SimConfig c;
  c.temperature_sensor.present = false;
  t.configure(c);
  double v = 7.0;
  CHECK(t.board().temperature.read(v) == hal::Status::closed);
  DOUBLES_EQUAL(7.0, v, 0.0);
}

TEST(SimTemperature, ALaggedSensorTrailsARampByRateTimesLag) {
  // GIVEN a resonator warming at r = 0.5 degC/s and a sensor with lag 0.2 s
  SimTarget t;
  SimConfig c;
  const double r = 0.5;
  const double tau = 0.2;
  c.temp_c = Profile::ramps({{0.0, 20.0}, {10.0, 20.0 + 10.0 * r}});
  c.temperature_sensor.lsb_c = 0.0;
  c.temperature_sensor.lag_s = tau;
  t.configure(c);
  // WHEN it is read every 1 ms block for 2 s (10 lags)
  double v = 0.0;
  for (int k = 0; k < 2000; ++k) {
    one_block(t);
    CHECK(t.board().temperature.read(v) == hal::Status::ok);
  }
  // THEN it trails by the discrete first-order lag's error
  // e_n = e (1 - (1 - a)^n), e = (1 - a) r dt / a, a = 1 - exp(-dt/tau)
  // (e -> r tau = 0.1 degC as dt -> 0)
  const double dt = 1e-3;
  const double a = -std::expm1(-dt / tau);
  const double e = (1.0 - a) * r * dt / a;
  DOUBLES_EQUAL(0.09975, e, 1e-5);
  DOUBLES_EQUAL(20.0 + 2.0 * r - e * (1.0 - std::pow(1.0 - a, 2000)), v, 1e-9);
}

TEST(SimTemperature, NoiseHasTheConfiguredRmsAndIsDeterministic) {
  SimConfig c;
  c.temp_c = Profile::constant(30.0);
  c.temperature_sensor.lsb_c = 0.0;
  c.temperature_sensor.noise_c_rms = 0.05;
  auto run = [&c](std::vector<double>& out) {
    SimTarget t;
    t.configure(c);
    for (int k = 0; k < 4000; ++k) {
      double v = 0.0;
      CHECK(t.board().temperature.read(v) == hal::Status::ok);
      out.push_back(v);
    }
  };
  std::vector<double> a, b;
  run(a);
  run(b);
  CHECK(a == b);
  double s2 = 0.0;
  for (double v : a)
    s2 += (v - 30.0) * (v - 30.0);
  // rms of 4000 draws: 0.05 within 5 sigma of its estimate (0.05 / sqrt(2 n))
  DOUBLES_EQUAL(0.05, std::sqrt(s2 / static_cast<double>(a.size())),
                5.0 * 0.05 / std::sqrt(8000.0));
}
