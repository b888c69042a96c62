#include "mesh_input.h"

#include "commands.h"

namespace shapedb::cli {

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
}

std::optional<MeshInput> loadMeshInput(const std::string& path, const MeshInputOptions& options) {
  Result<io::LoadedMesh> loaded = loadMeshFile(path, {.allowDegenerateFaces = options.allowDegenerate});
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
    if (mp.error().code == ErrorCode::kNotClosed || mp.error().code == ErrorCode::kNonManifold ||
        mp.error().code == ErrorCode::kInconsistentOrientation)
      hint = "; --approximate estimates from vertex point masses";
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
