// SPDX-License-Identifier: MIT
// `hrg`: host command line for the HRG whole-angle firmware reference.
#include <cstdio>
#include <span>
#include <string_view>

#include "hrg/command.hpp"

namespace {

void print_help(std::FILE* out) {
  std::fprintf(out,
               "usage: hrg <command> [options]\n\n"
               "Hemispherical resonator gyro (whole-angle mode): simulation, telemetry\n"
               "and audit tools.\n\ncommands:\n");
  for (const auto& c : hrg::cli::commands()) {
    std::fprintf(out, "  %-15.*s %.*s\n", static_cast<int>(c.name.size()), c.name.data(),
                 static_cast<int>(c.summary.size()), c.summary.data());
  }
  std::fprintf(out, "\n'hrg <command> --help' describes a command's options.\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_help(stderr);
    return 2;
  }
  const std::string_view name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_help(stdout);
    return 0;
  }
  for (const auto& c : hrg::cli::commands()) {
    if (c.name == name) return c.run(std::span<char* const>(argv + 2, argv + argc));
  }
  std::fprintf(stderr, "hrg: unknown command '%s'\n\n", argv[1]);
  print_help(stderr);
  return 2;
}
