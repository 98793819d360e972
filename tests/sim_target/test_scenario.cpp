// SPDX-License-Identifier: MIT
// Scenario files: the shipped default, units converted, bad input named.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "hal/board.hpp"
#include "sim_target/control.hpp"
#include "sim_target/scenario.hpp"

#include "support/cpputest.hpp"

using namespace hrg;
using namespace hrg::sim;

namespace {

std::string source_dir() {
  const char* d = std::getenv("HRG_SOURCE_DIR");
  return d ? d : ".";
}

std::string error_of(const std::string& text) {
  try {
    parse_scenario(text, "t.toml");
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_GROUP(Scenario){};

TEST(Scenario, DefaultFileIsTheSeedResonatorWithEarthRate) {
  const SimConfig c = load_scenario(source_dir() + "/sim_target/scenarios/default.toml");
  DOUBLES_EQUAL(5000.0, c.resonator.f_hz, 0.0);
  DOUBLES_EQUAL(5e6, c.resonator.q, 0.0);
  DOUBLES_EQUAL(0.05, c.resonator.dmu, 0.0);
  DOUBLES_EQUAL(5e-4, c.resonator.split_hz, 0.0);
  DOUBLES_EQUAL(0.554, c.resonator.angular_gain, 0.0);
  CHECK_EQUAL(100000u, c.adc.sample_rate_hz);
  CHECK(c.adc.noise_v_rms[0] > 0.0);
  // 7.2921159e-5 rad/s * sin(55.75 deg)
  DOUBLES_EQUAL(7.2921159e-5 * std::sin(55.75 * kDegToRad), c.rate_rad_s.value(123.0), 1e-18);
  CHECK_FALSE(c.effects.electrostatic_spring.enabled);
}

TEST(Scenario, DegreesAndDegreesPerSecondAreConvertedToSi) {
  const SimConfig c = parse_scenario(
      "[resonator]\nth_w_deg = 22.5\n[rate]\nkind = \"ramps\"\nt_s = [0, 10]\nvalue_dps = [0, 90]\n"
      "[effects.pickoff_phase_mismatch]\nenabled = true\nphase_deg = 1.5\n");
  DOUBLES_EQUAL(kPi / 8, c.resonator.th_w_rad, 1e-15);
  DOUBLES_EQUAL(kPi / 4, c.rate_rad_s.value(5.0), 1e-15);
  CHECK(c.effects.pickoff_phase_mismatch.enabled);
  DOUBLES_EQUAL(1.5, c.effects.pickoff_phase_mismatch.phase_deg, 0.0);
}

TEST(Scenario, UnknownKeysAreRejectedWithTheirDottedName) {
  CHECK(contains(error_of("[resonator]\nf_khz = 5\n"), "'resonator.f_khz': unknown key"));
  CHECK(contains(error_of("[effects.duffing_stiffness]\nkappa = 1\n"),
                 "'effects.duffing_stiffness.kappa': unknown key"));
  CHECK(
      contains(error_of("[effects.no_such_effect]\nenabled = true\n"), "'effects.no_such_effect'"));
  CHECK(contains(error_of("sed = 3\n"), "'sed': unknown key"));
}

TEST(Scenario, OutOfRangeValuesNameTheKeyAndTheAllowedRange) {
  const std::string e = error_of("[resonator]\nq = 5\n");
  CHECK(contains(e, "t.toml: key 'resonator.q': 5 is out of range [100, 1e+10]"));
  CHECK(contains(error_of("[adc]\nbits = 40\n"), "'adc.bits': 40 is out of range [2, 32]"));
  CHECK(contains(error_of("[rate]\nearth_latitude_deg = 91\n"),
                 "'rate.earth_latitude_deg': 91 is out of range [-90, 90] deg"));
  CHECK(contains(error_of("[resonator]\nf_hz = \"5k\"\n"), "'resonator.f_hz': must be a number"));
  CHECK(contains(error_of("[rate]\nkind = \"wobble\"\n"), "'rate.kind': 'wobble' is not one of"));
}

TEST(Scenario, SameSeedGivesTheSameBits) {
  SimConfig c = load_scenario(source_dir() + "/sim_target/scenarios/default.toml");
  std::vector<hal::q31_t> a(200);
  std::vector<hal::q31_t> b(200);
  uint64_t t_ns = 0;
  uint32_t clipped = 0;
  target().configure(c);
  hal::board().adc.read_block(a, t_ns, clipped);
  target().configure(c);
  hal::board().adc.read_block(b, t_ns, clipped);
  CHECK(a == b);
  c.seed = 2;
  target().configure(c);
  hal::board().adc.read_block(b, t_ns, clipped);
  CHECK(a != b);
  target().configure(SimConfig{});
}

TEST(Scenario, TableProfilesAreReadRelativeToTheScenarioFile) {
  const std::string dir = "test_scenario_dir";
  std::filesystem::create_directories(dir);
  std::FILE* f = std::fopen((dir + "/rate.csv").c_str(), "w");
  std::fputs("t_s,rate_dps\n0,0\n2,180\n", f);
  std::fclose(f);
  f = std::fopen((dir + "/s.toml").c_str(), "w");
  std::fputs("[rate]\nkind = \"table\"\nfile = \"rate.csv\"\n", f);
  std::fclose(f);
  const SimConfig c = load_scenario(dir + "/s.toml");
  DOUBLES_EQUAL(kPi / 2, c.rate_rad_s.value(1.0), 1e-15);
  f = std::fopen((dir + "/s.toml").c_str(), "w");
  std::fputs("[rate]\nkind = \"table\"\nfile = \"missing.csv\"\n", f);
  std::fclose(f);
  std::string err;
  try {
    load_scenario(dir + "/s.toml");
  } catch (const ScenarioError& e) {
    err = e.what();
  }
  CHECK(contains(err, "key 'rate.file': "));
  CHECK(contains(err, "missing.csv: cannot open profile table"));
  std::filesystem::remove_all(dir);
}
