// shapedb fracture: a closed mesh broken into fragments (OpenVDB level sets, Voronoi cells), written as
// mesh files.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/fracture.h>

#include "commands.h"

namespace shapedb::cli {
namespace {

struct FractureCommandOptions {
  MeshLoadFlags load;
  std::string mesh;
  std::string out;
  std::string format = "obj";
  volume::FractureOptions fracture;
};

int runFracture(const FractureCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  Result<volume::FractureResult> pieces = fractureMeshFile(o.mesh, o.load, o.fracture);
  if (!pieces) {
    printError(pieces.error().message);
    return kExitInputError;
  }
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  if (ec) {
    printError(o.out + ": " + ec.message());
    return kExitInputError;
  }
  for (std::size_t i = 0; i < pieces->fragments.size(); ++i) {
    const std::string name = volume::fragmentName(i) + "." + o.format;
    if (Status st = io::saveMesh(pieces->fragments[i], std::filesystem::path(o.out) / name); !st) {
      printError(st.error().message);
      return kExitInputError;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "%s: %zu fragments from %d seeds (seed %llu, resolution %d, voxel %.4g m) in %.2f s, written to %s "
      "(in metres)\n",
      o.mesh.c_str(), pieces->fragments.size(), o.fracture.pieces,
      static_cast<unsigned long long>(o.fracture.seed), pieces->resolution, pieces->voxelSize, seconds,
      o.out.c_str());
  std::printf("volume kept: %.2f %% of the solid's (%.4g of %.4g m3)", 100.0 * pieces->keptFraction(),
              pieces->keptVolume, pieces->solidVolume);
  if (pieces->crumbsDropped > 0)
    std::printf("; %zu crumb(s) under %.3g of the volume dropped", pieces->crumbsDropped,
                o.fracture.minVolumeFraction);
  if (pieces->openDropped > 0)
    std::printf("; %zu fragment(s) with no closed surface dropped", pieces->openDropped);
  if (pieces->droppedVolume > 0.0)
    std::printf(" (%.3g %% of the volume)", 100.0 * pieces->droppedVolume / pieces->solidVolume);
  if (pieces->remeshed > 0)
    std::printf("; %zu fragment(s) meshed slightly off the zero level to close", pieces->remeshed);
  std::printf("\n");
  return kExitOk;
}

}  // namespace

Result<volume::FractureResult> fractureMeshFile(const std::string& path, const MeshLoadFlags& load,
                                                const volume::FractureOptions& options) {
  Result<io::LoadedMesh> loaded = loadMeshFile(path, load);
  if (!loaded) return loaded.error();
  Result<volume::FractureResult> pieces = volume::fracture(loaded->mesh, options);
  if (!pieces) {
    Error error = withContext(pieces.error(), path);
    error.message += flagHint(pieces.error());
    return error;
  }
  return pieces;
}

void addFractureFlags(CLI::App& app, volume::FractureOptions& options) {
  app.add_option("--seed", options.seed, "Random seed: the same seed gives the same fragments")
      ->capture_default_str();
  app.add_option("--resolution", options.resolution,
                 "Level-set voxels along the mesh's longest side, 16 to 1,024 [default: automatic, 128 or\n"
                 "more where the solid or its pieces would be thin in voxels: at least 6 across its mean\n"
                 "thickness and 16 across a fragment, so that the cuts keep the volume]")
      ->check(CLI::Range(16, 1024));
  app.add_option("--max-triangles", options.maxTriangles,
                 "Simplify each fragment to this many triangles, as far as moving its surface by at most a\n"
                 "quarter voxel allows (fewer: coarser fragments, and far fewer tets computed directly)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{100}, std::size_t{1'000'000}));
}

CLI::Option* addFractureSourceFlags(CLI::App& app, std::string& mesh, volume::FractureOptions& options,
                                    const std::string& description) {
  CLI::Option* fracture = app.add_option("--fracture", mesh, description);
  app.add_option("--pieces", options.pieces, "With --fracture: Voronoi seeds")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000))
      ->needs(fracture);
  addFractureFlags(app, options);
  return fracture;
}

Command addFractureCommand(CLI::App& parent) {
  auto o = std::make_shared<FractureCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "fracture",
      "Break a closed mesh into fragments, as a fracture would: the solid becomes an OpenVDB level set, N\n"
      "random seeds inside it define Voronoi cells, and each cell's level set is intersected with it (a\n"
      "cell that cuts a non-convex solid in two gives two fragments). Fragments are closed meshes in the\n"
      "mesh's frame and in metres (a mesh read with --units is converted: query the fragments without\n"
      "it), largest first, with voxel-scale detail on the cuts; crumbs under 1e-4 of the volume\n"
      "are dropped. Deterministic per seed. 200 pieces of a plate take about 2 s.");
  app->add_option("MESH", o->mesh, "Closed surface mesh (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  app->add_option("--pieces", o->fracture.pieces, "Voronoi seeds (fragments, give or take)")
      ->required()
      ->check(CLI::Range(1, 1000));
  app->add_option("--out", o->out, "Directory for fragment-000.obj, fragment-001.obj, ...")->required();
  app->add_option("--format", o->format,
                  "File format of the fragments: obj or ply (double precision), or glb or gltf for a game\n"
                  "engine (single precision about each fragment's centre)")
      ->capture_default_str()
      ->check(CLI::IsMember({"obj", "ply", "glb", "gltf"}));
  addFractureFlags(*app, o->fracture);
  addMeshLoadFlags(*app, o->load);
  return {app, [o] { return runFracture(*o); }};
}

}  // namespace shapedb::cli
