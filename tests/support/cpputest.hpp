// SPDX-License-Identifier: MIT
#pragma once

// Include this last in every test file: CppUTest's leak-detection macros
// redefine new/delete and break Eigen and standard headers included after them.
#include <CppUTest/TestHarness.h>
