// clod command-line tool: dispatches to the registered subcommands (see command.h).
#include <cstdio>
#include <exception>
#include <new>
#include <iostream>
#include <string>

#include "clod/error.h"
#include "clod/version.h"
#include "command.h"

namespace clod::cli {

std::vector<RegisteredCommand>& registeredCommands() {
  static std::vector<RegisteredCommand> commands;
  return commands;
}

CommandRegistration::CommandRegistration(std::string name, CommandSetup setup) {
  registeredCommands().push_back({std::move(name), std::move(setup)});
}

}  // namespace clod::cli

int main(int argc, char** argv) {
  using namespace clod::cli;
  CLI::App app{"clod: time-critical collision detection and contact generation between rigid triangle meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("clod ") + clod::version());

  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (auto& command : registeredCommands()) {
    auto run = command.setup(app);
    runners.emplace_back(app.get_subcommand(command.name), std::move(run));
  }

  // CLI11 reports an unknown command as "A subcommand is required": name it instead.
  std::string known;
  bool isCommand = false;
  for (const auto& command : registeredCommands()) {
    known += (known.empty() ? "" : ", ") + command.name;
    isCommand = isCommand || (argc > 1 && command.name == argv[1]);
  }
  if (argc > 1 && argv[1][0] != '-' && !isCommand) {
    std::cerr << "clod: error [" << clod::errorCodeName(clod::ErrorCode::kInvalidArgument) << "]: unknown command '"
              << argv[1] << "' (commands: " << known << ")\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version: CLI11 prints them
    // Usage errors look like every other error (one line, code named), not like CLI11's text.
    std::cerr << "clod: error [" << clod::errorCodeName(clod::ErrorCode::kInvalidArgument) << "]: " << e.what()
              << " (see clod --help)\n";
    return 2;
  }

  try {
    for (auto& [sub, run] : runners) {
      if (sub && sub->parsed()) return run();
    }
  } catch (const clod::Error& e) {
    std::cerr << "clod: error [" << clod::errorCodeName(e.code()) << "]: " << e.what() << "\n";
    return e.code() == clod::ErrorCode::kInvalidArgument ? 2 : 1;
  } catch (const std::bad_alloc&) {
    // Limits that can be checked ahead are (README, "Limits"); what is left is the machine's.
    std::cerr << "clod: error [" << clod::errorCodeName(clod::ErrorCode::kResourceLimit)
              << "]: out of memory (std::bad_alloc); the input needs more memory than this machine gives\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "clod: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
