// SPDX-License-Identifier: MIT
// Instruction counts of the chain on the emulated Cortex-M7. QEMU runs with
// -icount shift=0 (one instruction = 1 ns of virtual time) and SysTick counts
// the 25 MHz system clock of mps2-an500, so one tick = 40 instructions.
// These are Thumb-2 instruction counts, not cycles (the M7 dual-issues).

#include <array>
#include <cstdint>
#include <span>

#include "dsp/chain.hpp"
#include "dsp/demodulator.hpp"
#include "report.hpp"
#include "semihosting.hpp"

namespace hrg::m7 {
void write_text(const char* s) { semihost_write0(s); }
}  // namespace hrg::m7

namespace {

using namespace hrg::dsp;

constexpr uint32_t kL = 100;
constexpr int kBlocks = 200;
constexpr int64_t kInstructionsPerTick = 40;

volatile uint32_t* const kSysTick = reinterpret_cast<volatile uint32_t*>(0xE000E010u);

void systick_start() {
  kSysTick[1] = 0xFFFFFFu;  // reload
  kSysTick[2] = 0u;         // current value
  kSysTick[0] = 5u;         // enable, processor clock, no interrupt
}
uint32_t systick_now() { return kSysTick[2]; }
int64_t instructions_since(uint32_t start) {
  return static_cast<int64_t>((start - systick_now()) & 0xFFFFFFu) * kInstructionsPerTick;
}

std::array<q31_t, 2 * kL> g_adc;
std::array<q31_t, 3 * kL> g_dac;

template <typename T>
int64_t fast_path_instructions() {
  static Demodulator<T> d(kL);
  uint32_t phase = 0;
  const uint32_t step = phase_step_of_hz(5000.0, 100000.0);
  QuadSample<T> q;
  const uint32_t t0 = systick_now();
  for (int b = 0; b < kBlocks; ++b)
    d.process_block(g_adc, phase, step, q);
  return instructions_since(t0);
}

template <typename T>
int64_t chain_instructions() {
  ChainConfig cfg;
  cfg.f_center_hz = 5000.2;
  static Chain<T> chain(cfg);
  chain.set_excitation(true);
  const uint32_t t0 = systick_now();
  for (int b = 0; b < kBlocks; ++b)
    chain.process(g_adc, g_dac);
  return instructions_since(t0);
}

}  // namespace

int main() {
  hrg::m7::Report r;
  uint32_t ph = 0;
  const uint32_t step = phase_step_of_hz(5000.0, 100000.0);
  for (uint32_t n = 0; n < kL; ++n) {
    g_adc[2 * n] = mul_q31_rnd(0x40000000, sin_turns<q31_t>(ph));
    g_adc[2 * n + 1] = mul_q31_rnd(0x0CCCCCCC, sin_turns<q31_t>(ph + 0x10000000u));
    ph += step;
  }
  systick_start();
  const int64_t frames = static_cast<int64_t>(kBlocks) * kL;
  r.figure("m7 fast path q31, instructions per frame (x and y)",
           fast_path_instructions<q31_t>() / frames);
  r.figure("m7 fast path f32, instructions per frame (x and y)",
           fast_path_instructions<float>() / frames);
  r.figure("m7 whole chain q31, instructions per block", chain_instructions<q31_t>() / kBlocks);
  r.figure("m7 whole chain f32, instructions per block", chain_instructions<float>() / kBlocks);
  return 0;
}
