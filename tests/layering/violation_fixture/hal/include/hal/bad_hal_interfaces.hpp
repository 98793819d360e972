// SPDX-License-Identifier: MIT
// Fixture for the layering check's own test: this include must be caught.
#pragma once
#include "hal/linux/socket_can.hpp"
