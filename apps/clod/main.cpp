// clod command-line tool: dispatches to the registered subcommands (see command.h).
#include <cstdio>
#include <exception>
#include <iostream>

#include "clod/error.h"
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
  app.set_version_flag("--version", "clod 0.1.0");

  std::vector<std::pair<CLI::App*, std::function<int()>>> runners;
  for (auto& command : registeredCommands()) {
    auto run = command.setup(app);
    runners.emplace_back(app.get_subcommand(command.name), std::move(run));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);  // prints help or the usage error
    return code == 0 ? 0 : 2;
  }

  try {
    for (auto& [sub, run] : runners) {
      if (sub && sub->parsed()) return run();
    }
  } catch (const clod::Error& e) {
    std::cerr << "clod: error [" << clod::errorCodeName(e.code()) << "]: " << e.what() << "\n";
    return e.code() == clod::ErrorCode::kInvalidArgument ? 2 : 1;
  } catch (const std::exception& e) {
    std::cerr << "clod: error: " << e.what() << "\n";
    return 1;
  }
  return 2;
}
