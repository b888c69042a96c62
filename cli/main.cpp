#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <shapedb/volume/openvdb_runtime.h>

#include "commands.h"

namespace shapedb::cli {

void printError(const std::string& message) {
  std::fprintf(stderr, "shapedb: %s\n", message.c_str());
}

namespace {

/// The modal analyses of a build and of the geometry correction allocate and free sparse matrices and
/// factors of megabytes, one after another. By default glibc maps large blocks fresh from the kernel and
/// unmaps them when freed, and gives the top of its heap back too, so that every first touch of a page
/// of the next one faults (on a VM, ~10 µs each). Blocks under 32 MB are kept in the heap instead, and
/// freed memory goes back to the kernel only beyond 256 MB: two real meshes' corrections took 30,000
/// page faults instead of 47,000 and 6-11 % less time. Left alone when the user tunes malloc through
/// GLIBC_TUNABLES.
void keepFreedMemory() {
#if defined(__GLIBC__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.")) return;
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

}  // namespace

}  // namespace shapedb::cli

int main(int argc, char** argv) {
  using namespace shapedb::cli;
  keepFreedMemory();
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
