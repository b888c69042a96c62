#include <cstdio>
#include <exception>
#include <vector>

#include <shapedb/volume/openvdb_runtime.h>

#include "commands.h"

namespace shapedb::cli {

void printError(const std::string& message) {
  std::fprintf(stderr, "shapedb: %s\n", message.c_str());
}

}  // namespace shapedb::cli

int main(int argc, char** argv) {
  using namespace shapedb::cli;
  CLI::App app{
      "shapedb: physical data for objects that have only a surface mesh, from a precomputed shape database.\n"
      "Run 'shapedb COMMAND --help' for the options of a command."};
  app.set_version_flag("--version", std::string("shapedb " SHAPEDB_VERSION " (OpenVDB ") +
                                        shapedb::volume::openVdbVersion() + ")");
  app.require_subcommand(1);
  std::vector<Command> commands = {addInspectCommand(app),  addDescribeCommand(app), addBuildCommand(app),
                                   addInfoCommand(app),     addAddCommand(app),      addMergeCommand(app),
                                   addEnrichCommand(app),   addQueryCommand(app),    addHapticCommand(app),
                                   addFractureCommand(app), addBenchCommand(app),    addSoundCommand(app),
                                   addDropCommand(app)};

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }

  // The one top-level catch: library errors come back as values; an exception here is a bug.
  try {
    for (const Command& command : commands)
      if (command.app->parsed()) return command.run();
  } catch (const std::exception& e) {
    printError(std::string("internal error: ") + e.what());
    return kExitInternal;
  }
  return kExitUsage;
}
