// SPDX-License-Identifier: MIT
#include "dsp/fixed.hpp"
