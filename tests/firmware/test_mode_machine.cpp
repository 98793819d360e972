// SPDX-License-Identifier: MIT
#include "firmware/mode_machine.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

#include "support/cpputest.hpp"

using hrg::fw::Event;
using hrg::fw::Fault;
using hrg::fw::fault_bit;
using hrg::fw::Mode;
using hrg::fw::ModeMachine;

namespace {

// Drives a fresh machine to `target` along the normal path.
ModeMachine machine_in(Mode target) {
  ModeMachine m;
  const auto step = [&](Event e) { m.handle(e, fault_bit(Fault::loss_of_lock)); };
  switch (target) {
    case Mode::power_up: break;
    case Mode::ring_up: step(Event::self_test_passed); break;
    case Mode::lock:
      step(Event::self_test_passed);
      step(Event::amplitude_reached);
      break;
    case Mode::operate:
      step(Event::self_test_passed);
      step(Event::amplitude_reached);
      step(Event::loops_settled);
      break;
    case Mode::free_decay:
      m = machine_in(Mode::operate);
      m.handle(Event::window_open);
      break;
    case Mode::recover:
      m = machine_in(Mode::free_decay);
      m.handle(Event::window_close);
      break;
    case Mode::fault:
      m = machine_in(Mode::operate);
      m.handle(Event::fault_detected, fault_bit(Fault::loss_of_lock));
      break;
    case Mode::safe: m.handle(Event::command_safe); break;
  }
  return m;
}

constexpr std::array<Mode, 8> kAllModes{Mode::power_up,   Mode::ring_up, Mode::lock,  Mode::operate,
                                        Mode::free_decay, Mode::recover, Mode::fault, Mode::safe};

}  // namespace

TEST_GROUP(ModeMachine){};

TEST(ModeMachine, StartsInPowerUpWithDrivesAndEnableOff) {
  ModeMachine m;
  CHECK(Mode::power_up == m.mode());
  CHECK_FALSE(m.permissions().pump);
  CHECK_FALSE(m.permissions().forcers);
  CHECK_FALSE(m.permissions().enable_line);
}

TEST(ModeMachine, EveryRowOfTheTableMovesFromItsModeToItsTarget) {
  for (const auto& t : hrg::fw::kTransitions) {
    ModeMachine m = machine_in(t.from);
    CHECK(t.from == m.mode());
    m.handle(t.event, fault_bit(Fault::loss_of_lock));
    if (t.to != m.mode()) {
      FAIL(hrg::fw::to_string(t.event));
    }
  }
}

TEST(ModeMachine, EveryPairNotInTheTableIsIgnoredAndCounted) {
  for (Mode from : kAllModes) {
    for (std::size_t e = 0; e < hrg::fw::kEventCount; ++e) {
      const auto ev = static_cast<Event>(e);
      Mode to = from;
      if (hrg::fw::lookup_transition(from, ev, to)) continue;
      ModeMachine m = machine_in(from);
      const uint32_t ignored = m.ignored_events();
      CHECK_FALSE(m.handle(ev, fault_bit(Fault::adc_stuck)));
      CHECK(from == m.mode());
      LONGS_EQUAL(ignored + 1, m.ignored_events());
    }
  }
}

TEST(ModeMachine, TheNormalCycleRunsWindowsAndReturnsToOperate) {
  ModeMachine m = machine_in(Mode::operate);
  for (int i = 0; i < 3; ++i) {
    CHECK(m.handle(Event::window_open));
    CHECK(Mode::free_decay == m.mode());
    CHECK(m.handle(Event::window_close));
    CHECK(Mode::recover == m.mode());
    CHECK(m.handle(Event::reacquired));
    CHECK(Mode::operate == m.mode());
  }
}

TEST(ModeMachine, EachRecoverableFaultFromEachActiveModeGoesToFaultAndLatchesItsBit) {
  constexpr std::array<Fault, 5> kRecoverable{Fault::loss_of_lock, Fault::amplitude_collapse,
                                              Fault::adc_saturation, Fault::adc_stuck,
                                              Fault::overrun_storm};
  constexpr std::array<Mode, 5> kActive{Mode::ring_up, Mode::lock, Mode::operate, Mode::free_decay,
                                        Mode::recover};
  for (Fault f : kRecoverable) {
    for (Mode from : kActive) {
      ModeMachine m = machine_in(from);
      CHECK(m.handle(Event::fault_detected, fault_bit(f)));
      CHECK(Mode::fault == m.mode());
      LONGS_EQUAL(fault_bit(f), m.faults());
      // Drives are off in fault; the enable line stays up for the retry.
      CHECK_FALSE(m.permissions().pump);
      CHECK_FALSE(m.permissions().forcers);
      CHECK_FALSE(m.permissions().output_valid);
    }
  }
}

TEST(ModeMachine, AFaultDuringSelfTestGoesStraightToSafe) {
  ModeMachine m;
  m.handle(Event::fault_detected, fault_bit(Fault::adc_stuck));
  CHECK(Mode::safe == m.mode());
}

TEST(ModeMachine, DriveElectronicsFaultsGoToSafeFromEveryMode) {
  for (Fault f : {Fault::dac_fault, Fault::external}) {
    for (Mode from : kAllModes) {
      ModeMachine m = machine_in(from);
      m.handle(Event::fault_detected, fault_bit(f));
      CHECK(Mode::safe == m.mode());
      CHECK((m.faults() & fault_bit(f)) != 0);
    }
  }
}

TEST(ModeMachine, RecoveryFromFaultRestartsRingUpAndAReachedOperateClearsTheEpisode) {
  ModeMachine m = machine_in(Mode::fault);
  CHECK(m.handle(Event::fault_cleared));
  CHECK(Mode::ring_up == m.mode());
  LONGS_EQUAL(1, m.retries());
  m.handle(Event::amplitude_reached);
  m.handle(Event::loops_settled);
  CHECK(Mode::operate == m.mode());
  LONGS_EQUAL(0, m.retries());
  LONGS_EQUAL(0, m.faults());
}

TEST(ModeMachine, RepeatedFaultsExhaustTheRetriesAndEndInSafe) {
  ModeMachine m(2);
  m.handle(Event::self_test_passed);
  for (int attempt = 0; attempt < 2; ++attempt) {
    m.handle(Event::fault_detected, fault_bit(Fault::amplitude_collapse));
    CHECK(Mode::fault == m.mode());
    m.handle(Event::fault_cleared);
    CHECK(Mode::ring_up == m.mode());
  }
  m.handle(Event::fault_detected, fault_bit(Fault::amplitude_collapse));
  m.handle(Event::fault_cleared);
  CHECK(Mode::safe == m.mode());
}

TEST(ModeMachine, SafeHasDrivesAndEnableOffAndLeavesOnlyOnRestart) {
  ModeMachine m = machine_in(Mode::safe);
  CHECK_FALSE(m.permissions().pump);
  CHECK_FALSE(m.permissions().forcers);
  CHECK_FALSE(m.permissions().enable_line);
  CHECK_FALSE(m.permissions().output_valid);
  CHECK_FALSE(m.handle(Event::fault_cleared));
  CHECK_FALSE(m.handle(Event::self_test_passed));
  CHECK(m.handle(Event::command_restart));
  CHECK(Mode::power_up == m.mode());
}

TEST(ModeMachine, FreeDecayHasDrivesOffButTheOutputStaysValid) {
  const auto& p = hrg::fw::policy(Mode::free_decay);
  CHECK_FALSE(p.pump);
  CHECK_FALSE(p.forcers);
  CHECK(p.output_valid);
  CHECK(p.identify);
}

TEST(ModeMachine, PolicyTableIsIndexedByMode) {
  for (Mode m : kAllModes)
    CHECK(m == hrg::fw::policy(m).mode);
}
