#pragma once
// Subcommand registry of the clod CLI. Each cmd_<name>.cpp defines one subcommand and
// registers it with a static CommandRegistration; main.cpp knows none of them by name.
//
// Exit codes: 0 success, 1 bad input data (unreadable/invalid file, mesh, scene),
// 2 bad usage (unknown option, out-of-range argument). Messages go to stderr.

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace clod::cli {

/// Adds a subcommand to `app` and returns the function to run when it is chosen.
/// The function returns the process exit code.
using CommandSetup = std::function<std::function<int()>(CLI::App& app)>;

struct CommandRegistration {
  CommandRegistration(std::string name, CommandSetup setup);
};

struct RegisteredCommand {
  std::string name;
  CommandSetup setup;
};
std::vector<RegisteredCommand>& registeredCommands();

}  // namespace clod::cli
