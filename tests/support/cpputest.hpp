// SPDX-License-Identifier: MIT
#pragma once

// Include this last in every test file: CppUTest's leak-detection macros
// redefine new/delete and break Eigen and standard headers included after them.
#include <CppUTest/TestHarness.h>

// A test group whose code under test keeps process-wide state that outlives
// each test (the simulated target's singleton and its buffers, a batch's
// worker threads, a study's caches): those allocations are not the test's
// leaks, so CppUTest's new/delete tracking is off for the group's tests.
#define TEST_GROUP_WITHOUT_LEAK_CHECK(group)                                               \
  TEST_GROUP(group) {                                                                      \
    void setup() override { MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); } \
    void teardown() override { MemoryLeakWarningPlugin::restoreNewDeleteOverloads(); }     \
  }
