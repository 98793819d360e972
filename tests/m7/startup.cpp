// SPDX-License-Identifier: MIT
// Bare-metal start-up for QEMU's mps2-an500 (Cortex-M7, FPv5 double
// precision): vector table, FPU enable, .bss zeroing, constructors, main,
// and exit through semihosting so QEMU returns the test's status.

#include <cstdint>

#include "semihosting.hpp"

extern "C" {
extern uint32_t __stack_top;
extern uint32_t __bss_start__;
extern uint32_t __bss_end__;
extern void (*__init_array_start)();
extern void (*__init_array_end)();
int main();
[[noreturn]] void reset_handler();
[[noreturn]] void fault_handler();
}

// Enables CP10/CP11 (the FPU) before any floating-point instruction runs:
// this function is naked so the compiler cannot schedule FP code ahead of it.
extern "C" [[noreturn]] __attribute__((naked)) void reset_handler() {
  asm volatile(
      "ldr r0, =0xE000ED88\n"  // CPACR
      "ldr r1, [r0]\n"
      "orr r1, r1, #(0xF << 20)\n"
      "str r1, [r0]\n"
      "dsb\n"
      "isb\n"
      "b hrg_m7_start\n");
}

extern "C" [[noreturn]] void hrg_m7_start() {
  for (uint32_t* p = &__bss_start__; p < &__bss_end__; ++p)
    *p = 0;
  for (void (**f)() = &__init_array_start; f < &__init_array_end; ++f)
    (*f)();
  const int rc = main();
  hrg::m7::semihost_exit(rc == 0);
}

extern "C" [[noreturn]] void fault_handler() {
  hrg::m7::semihost_write0("FAIL: processor fault\n");
  hrg::m7::semihost_exit(false);
}

// Initial stack pointer, reset and the fault vectors; the suite uses no
// interrupts, so the rest of the table stays empty.
__attribute__((section(".vectors"), used))
const uintptr_t kVectors[16] = {reinterpret_cast<uintptr_t>(&__stack_top),
                                reinterpret_cast<uintptr_t>(&reset_handler),
                                reinterpret_cast<uintptr_t>(&fault_handler),  // NMI
                                reinterpret_cast<uintptr_t>(&fault_handler),  // HardFault
                                reinterpret_cast<uintptr_t>(&fault_handler),  // MemManage
                                reinterpret_cast<uintptr_t>(&fault_handler),  // BusFault
                                reinterpret_cast<uintptr_t>(&fault_handler),  // UsageFault
                                0,
                                0,
                                0,
                                0,
                                0,
                                0,
                                0,
                                0,
                                0};
