// SPDX-License-Identifier: MIT
// hrg::hal::board() of the simulated target (library hrg_board_sim). Kept out
// of hrg_sim_target so that a program can use the simulation's converters on
// another target's board (hrg-board links hrg_board_linux): the target behind
// hal::board() is the one library of the two that the program links.
#include "sim_target/control.hpp"

namespace hrg::sim {

SimTarget& target() {
  static SimTarget instance;
  return instance;
}

}  // namespace hrg::sim

namespace hrg::hal {

Board& board() { return sim::target().board(); }

}  // namespace hrg::hal
