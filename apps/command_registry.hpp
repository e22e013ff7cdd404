// Each subcommand lives in its own apps/cmd_<name>.cpp and registers itself here, so the
// command line grows without one file that knows every command.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace scfloam::cli {

struct CommandEntry {
  std::string name;
  // Adds the subcommand (its options and callback) to the application.
  std::function<void(CLI::App&)> add;
};

std::vector<CommandEntry>& command_registry();

struct RegisterCommand {
  RegisterCommand(std::string name, std::function<void(CLI::App&)> add) {
    command_registry().push_back({std::move(name), std::move(add)});
  }
};

}  // namespace scfloam::cli
