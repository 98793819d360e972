// SPDX-License-Identifier: MIT
// Fixture for the layering check's own test: this include must be caught.
#pragma once
#include "dsp/chain.hpp"
