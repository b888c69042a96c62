#include "mesh_input.h"

#include <cstdio>
#include <string>
#include <vector>

#include "commands.h"

namespace shapedb::cli {

std::string flagHint(const Error& error) {
  if (error.code == ErrorCode::kNotClosed || error.code == ErrorCode::kNonManifold)
    return "; if its vertices only nearly coincide, --weld-tolerance F (say 1e-6) welds them; --repair "
           "closes small holes and remeshes a non-manifold surface";
  if (error.code == ErrorCode::kInconsistentOrientation)
    return "; --repair remeshes it as one consistently oriented surface";
  if (error.code == ErrorCode::kSelfIntersecting) return "; --repair remeshes it as the solid it encloses";
  return "";
}

bool boundsNoSolid(const Error& error) {
  return error.code == ErrorCode::kNotClosed || error.code == ErrorCode::kNonManifold ||
         error.code == ErrorCode::kInconsistentOrientation;
}

void addMeshLoadFlags(CLI::App& app, MeshLoadFlags& flags) {
  CLI::Option* units =
      app.add_option_function<std::string>(
             "--units",
             [&flags](const std::string& unit) {
               flags.units = unit;
               flags.options.scale = *io::unitScale(unit);
             },
             "The mesh files' unit: mm, cm, m, in or ft [default: m; a mesh over 10 m or under 1 mm across\n"
             "gets a warning naming the likely unit]")
          ->check(CLI::IsMember({"mm", "cm", "m", "in", "ft"}));
  app.add_option_function<double>(
         "--scale",
         [&flags](double scale) {
           flags.units = "scale";
           flags.options.scale = scale;
         },
         "Multiply the mesh files' coordinates by this to get metres")
      ->check(CLI::PositiveNumber)
      ->excludes(units);
  CLI::Option* repair = app.add_flag(
      "--repair", flags.repair,
      "Make a closed surface of an open, non-manifold or self-intersecting one: holes up to a tenth\n"
      "of the mesh across are shut, the rest stays within a voxel (a level set; prints what changed)");
  app.add_option("--repair-resolution", flags.repairOptions.resolution,
                 "With --repair: voxels along the mesh's largest side")
      ->capture_default_str()
      ->check(CLI::Range(16, 1024))
      ->needs(repair);
  app.add_flag_function(
      "--keep-specks", [&flags](std::int64_t) { flags.options.dropSpecks = false; },
      "Keep a mesh's detached parts under 0.001 of its largest part's area (a scan's floating specks),\n"
      "which are otherwise dropped with a warning");
  app.add_option("--weld-tolerance", flags.options.weldTolerance,
                 "An open surface's vertices closer than this fraction of its bounding box's diagonal are\n"
                 "welded into one (exactly coincident ones always are)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.01));
}

Result<io::LoadedMesh> loadMeshFile(const std::string& path, const MeshLoadFlags& flags,
                                    std::optional<volume::RepairReport>* repaired,
                                    std::vector<std::string>& messages) {
  Result<io::LoadedMesh> loaded = io::loadMesh(path, flags.options);
  if (!loaded) return loaded;
  for (const std::string& note : loaded->notes())
    messages.push_back("shapedb: warning: " + path + ": " + note);
  char line[1024];
  if (flags.repair) {
    Result<volume::RepairedSurface> repair = volume::repairSurface(loaded->mesh, flags.repairOptions);
    if (!repair) return withContext(repair.error(), path + ": --repair");
    const volume::RepairReport& r = repair->report;
    char volume[96];
    if (r.volumeBefore)
      std::snprintf(volume, sizeof volume, "volume %.4g -> %.4g (%+.2f %%)", *r.volumeBefore, r.volumeAfter,
                    100.0 * (r.volumeAfter / *r.volumeBefore - 1.0));
    else
      std::snprintf(volume, sizeof volume, "volume %.4g (none before: not closed)", r.volumeAfter);
    std::snprintf(line, sizeof line,
                  "repaired at %d voxels (%.3g each): %zu holes shut (closing radius %.3g), %s, area %.4g -> "
                  "%.4g, %zu -> %zu triangles",
                  r.resolution, r.voxelSize, r.holes, r.closingRadius, volume, r.areaBefore, r.areaAfter,
                  r.trianglesBefore, r.trianglesAfter);
    messages.push_back("shapedb: note: " + path + ": " + line);
    loaded->mesh = std::move(repair->mesh);
    loaded->topology = core::analyzeTopology(loaded->mesh);
    if (repaired) *repaired = r;
  }
  if (flags.units.empty() && !loaded->mesh.vertices.empty()) {
    const core::Bounds bounds = core::computeBounds(loaded->mesh);
    const double size = (bounds.max - bounds.min).maxCoeff();
    if (size > 1e4) {  // millimetres would still leave it over 10 m
      std::snprintf(line, sizeof line,
                    "the mesh is %.4g km across, read in metres; if that is not its unit, give --units or "
                    "--scale",
                    size * 1e-3);
      messages.push_back("shapedb: warning: " + path + ": " + line);
    } else if (size > 10.0) {
      std::snprintf(line, sizeof line,
                    "the mesh is %.4g m across, read in metres; if its unit is millimetres (as CAD exports "
                    "often are), give --units mm (inches: --units in)",
                    size);
      messages.push_back("shapedb: warning: " + path + ": " + line);
    } else if (size < 1e-3) {
      std::snprintf(line, sizeof line,
                    "the mesh is %.3g mm across, read in metres; if that is not its unit, give --units or "
                    "--scale",
                    size * 1e3);
      messages.push_back("shapedb: warning: " + path + ": " + line);
    }
  }
  return loaded;
}

Result<io::LoadedMesh> loadMeshFile(const std::string& path, const MeshLoadFlags& flags,
                                    std::optional<volume::RepairReport>* repaired) {
  std::vector<std::string> messages;
  Result<io::LoadedMesh> loaded = loadMeshFile(path, flags, repaired, messages);
  for (const std::string& m : messages)
    std::fprintf(stderr, "%s\n", m.c_str());
  return loaded;
}

void addMeshInputFlags(CLI::App& app, MeshInputOptions& options) {
  app.add_option("--density", options.density, "Density in kg/m³ for mass and inertia")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag(
      "--approximate", options.approximate,
      "Accept an open or non-manifold surface: estimate from vertex point masses (marked approximate)");
  app.add_flag("--flip-inside-out", options.flipInsideOut, "Accept a mesh wound inward by flipping it");
  app.add_flag("--allow-degenerate", options.allowDegenerate,
               "Accept degenerate faces (dropped if a vertex repeats, kept if only their area is zero)");
  addMeshLoadFlags(app, options.load);
}

std::optional<MeshInput> loadMeshInput(const std::string& path, const MeshInputOptions& options) {
  MeshLoadFlags load = options.load;
  load.options.allowDegenerateFaces = options.allowDegenerate;
  Result<io::LoadedMesh> loaded = loadMeshFile(path, load);
  if (!loaded) {
    printError(loaded.error().message);
    return std::nullopt;
  }
  const core::MassPropertiesOptions massOptions{.density = options.density,
                                                .flipInsideOut = options.flipInsideOut,
                                                .allowApproximate = options.approximate};
  Result<core::MassProperties> mp = core::computeMassProperties(loaded->mesh, loaded->topology, massOptions);
  if (!mp) {
    std::string hint;
    if (mp.error().code == ErrorCode::kInsideOut) hint = "; --flip-inside-out flips it";
    if (boundsNoSolid(mp.error()))
      hint = "; --approximate estimates from vertex point masses" + flagHint(mp.error());
    printError(path + ": " + mp.error().message + hint);
    return std::nullopt;
  }
  Result<core::Normalization> n = core::normalize(loaded->mesh, *mp);
  if (!n) {
    printError(path + ": " + n.error().message);
    return std::nullopt;
  }
  return MeshInput{std::move(loaded).value(), std::move(mp).value(), std::move(n).value()};
}

}  // namespace shapedb::cli
