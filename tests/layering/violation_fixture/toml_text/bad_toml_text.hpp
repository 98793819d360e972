// SPDX-License-Identifier: MIT
// Fixture for the layering check's own test: this include must be caught.
#pragma once
#include "sim_target/scenario.hpp"
