#pragma once

// Subcommands of the shapedb executable. Each is thin: it parses, calls the library, and prints.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include <shapedb/core/result.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/fracture.h>
#include <shapedb/volume/repair.h>

namespace shapedb::cli {

/// Exit codes shared by every subcommand.
enum ExitCode : int {
  kExitOk = 0,
  kExitInputError = 1,  ///< the input was bad: a one-line message on stderr says why
  kExitUsage = 2,       ///< the command line was bad
  kExitInternal = 3,    ///< a bug: an unexpected exception reached main
};

/// A registered subcommand: its CLI11 node and what to run when it is chosen.
struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command addInspectCommand(CLI::App& parent);
Command addDescribeCommand(CLI::App& parent);
Command addBuildCommand(CLI::App& parent);
Command addInfoCommand(CLI::App& parent);
Command addAddCommand(CLI::App& parent);
Command addMergeCommand(CLI::App& parent);
Command addEnrichCommand(CLI::App& parent);
Command addQueryCommand(CLI::App& parent);
Command addHapticCommand(CLI::App& parent);
Command addFractureCommand(CLI::App& parent);
Command addBenchCommand(CLI::App& parent);
Command addSoundCommand(CLI::App& parent);
Command addDropCommand(CLI::App& parent);

/// How the mesh files a command reads are interpreted: their unit and welding (--units, --scale,
/// --weld-tolerance), on every command that reads meshes.
struct MeshLoadFlags {
  io::LoadOptions options;
  std::string units;    ///< as given ("" when neither --units nor --scale was)
  bool repair = false;  ///< --repair: volume::repairSurface after loading
  volume::RepairOptions repairOptions;
};

/// Loads a mesh file and fractures it; errors name the file. Shared by fracture and haptic --fracture.
Result<volume::FractureResult> fractureMeshFile(const std::string& path, const MeshLoadFlags& load,
                                                const volume::FractureOptions& options);
/// Adds --seed, --resolution and --max-triangles for `options`.
void addFractureFlags(CLI::App& app, volume::FractureOptions& options);
/// For a command that can take a mesh's fragments in place of its meshes: --fracture MESH (`description`
/// says what the fragments stand for), --pieces, which needs it, and addFractureFlags. Returns --fracture.
CLI::Option* addFractureSourceFlags(CLI::App& app, std::string& mesh, volume::FractureOptions& options,
                                    const std::string& description);

/// Prints "shapedb: <message>" on stderr, one line.
void printError(const std::string& message);

/// The flag that would get past a refusal of a mesh, as "; --flag ..." to append to its message, or "".
std::string flagHint(const Error& error);

/// Whether `error` refuses a surface for bounding no well-defined solid (open, non-manifold, inconsistently
/// oriented): what --approximate gets past.
bool boundsNoSolid(const Error& error);

/// Adds --units, --scale, --weld-tolerance, --repair and --repair-resolution to `app`.
void addMeshLoadFlags(CLI::App& app, MeshLoadFlags& flags);

/// io::loadMesh, and what it did to the file's mesh (a surface wound inward and flipped, vertices
/// welded) printed on stderr as "shapedb: warning: <file>: <note>"; so is a size that suggests another
/// unit than metres, when none was given. With flags.repair, the mesh is then repaired
/// (volume::repairSurface), what the repair did printed as a note, and given in `repaired` when asked.
/// Every command that reads a mesh file reads it through this.
Result<io::LoadedMesh> loadMeshFile(const std::string& path, const MeshLoadFlags& flags = {},
                                    std::optional<volume::RepairReport>* repaired = nullptr);

/// The same, with the lines it would print on stderr appended to `messages` instead, in order: for
/// files loaded side by side whose messages are printed afterwards in the files' order.
Result<io::LoadedMesh> loadMeshFile(const std::string& path, const MeshLoadFlags& flags,
                                    std::optional<volume::RepairReport>* repaired,
                                    std::vector<std::string>& messages);

}  // namespace shapedb::cli
