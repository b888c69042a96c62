#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include <shapedb/core/descriptor.h>
#include <shapedb/volume/describe.h>

#include "commands.h"
#include "format.h"
#include "mesh_input.h"

namespace shapedb::cli {
namespace {

struct DescribeOptions {
  std::string meshPath;
  std::string kind = "centroid-voxel";
  std::string sampling = "area";
  int grid = 10;
  bool json = false;
  MeshInputOptions input;
};

nlohmann::json descriptorJson(const DescribeOptions& options, const core::Descriptor& d,
                              const core::Normalization& n) {
  nlohmann::json out = {{"file", options.meshPath},
                        {"descriptor", core::toString(d.kind)},
                        {"moments", toJson(d.moments)},
                        {"transform", toJson(n.canonicalFromMesh)}};
  if (d.kind == core::DescriptorKind::kMoment) return out;
  const std::size_t cells = static_cast<std::size_t>(d.gridSize) * d.gridSize * d.gridSize;
  std::vector<int> occupancy(cells, 0);
  nlohmann::json centroids(cells, nullptr);
  for (std::size_t i = 0; i < d.cells.size(); ++i) {
    occupancy[d.cells[i]] = 1;
    centroids[d.cells[i]] = toJson(d.canonicalCentroid(i));
  }
  out["sampling"] = core::toString(d.sampling);
  out["grid"] = d.gridSize;
  out["cell_size"] = d.cellSize;
  out["filled_cells"] = d.cells.size();
  out["occupancy"] = occupancy;
  if (d.kind == core::DescriptorKind::kCentroidVoxel) out["centroids"] = std::move(centroids);
  return out;
}

// The grid as z slices side by side, y up, x to the right: '#' filled, '.' empty.
void printSlices(const core::Descriptor& d) {
  const int n = d.gridSize;
  std::vector<char> filled(static_cast<std::size_t>(n) * n * n, 0);
  for (std::uint32_t c : d.cells)
    filled[c] = 1;
  const int perRow = std::max(1, 100 / (n + 2));
  for (int first = 0; first < n; first += perRow) {
    const int last = std::min(n, first + perRow);
    for (int k = first; k < last; ++k)
      std::printf("%-*s", n + 2, ("z=" + std::to_string(k)).c_str());
    std::printf("\n");
    for (int j = n - 1; j >= 0; --j) {
      for (int k = first; k < last; ++k) {
        for (int i = 0; i < n; ++i)
          std::putchar(filled[static_cast<std::size_t>(i + n * (j + n * k))] ? '#' : '.');
        std::printf("  ");
      }
      std::printf("\n");
    }
    std::printf("\n");
  }
}

int runDescribe(const DescribeOptions& options) {
  std::optional<MeshInput> input = loadMeshInput(options.meshPath, options.input);
  if (!input) return kExitInputError;
  core::DescriptorOptions descriptorOptions;
  descriptorOptions.kind = *core::parseDescriptorKind(options.kind);
  descriptorOptions.sampling = *core::parseSampling(options.sampling);
  descriptorOptions.gridSize = options.grid;
  Result<core::Descriptor> d = volume::describe(input->loaded.mesh, input->normalization, descriptorOptions);
  if (!d) {
    printError(options.meshPath + ": " + d.error().message);
    return kExitInputError;
  }
  if (options.json) {
    std::printf("%s\n", descriptorJson(options, *d, input->normalization).dump(2).c_str());
    return kExitOk;
  }
  std::printf("%s: %s descriptor\n", options.meshPath.c_str(), core::toString(d->kind));
  std::printf("moments (unit volume, unit density, ascending) %s\n", toText(d->moments).c_str());
  if (d->kind == core::DescriptorKind::kMoment) return kExitOk;
  std::printf("grid %d³, cell %.6g (canonical units), %s sampling: %zu of %d cells filled\n", d->gridSize,
              d->cellSize, core::toString(d->sampling), d->cells.size(),
              d->gridSize * d->gridSize * d->gridSize);
  if (input->normalization.isDegenerate() || input->normalization.signAmbiguous[0] ||
      input->normalization.signAmbiguous[1])
    std::printf(
        "note: the canonical frame is not fully determined (axes %s); a query tries other orientations\n",
        core::toString(input->normalization.degeneracy));
  printSlices(*d);
  return kExitOk;
}

}  // namespace

Command addDescribeCommand(CLI::App& parent) {
  auto options = std::make_shared<DescribeOptions>();
  CLI::App* app = parent.add_subcommand(
      "describe",
      "Compute the shape descriptor a query uses (paper §4) for a surface mesh in its canonical frame:\n"
      "moment (the three principal moments of the unit-volume shape), voxel (occupancy of an N³ grid\n"
      "centred on the centre of mass, side = the largest extent), or centroid-voxel (occupancy plus the\n"
      "centroid of the surface in each filled cell). Prints the grid as z slices, or JSON with --json:\n"
      "'moments'; 'grid', 'occupancy' (N³ values 0/1, x fastest); 'centroids' (N³ entries, [x, y, z] in\n"
      "the canonical frame or null for an empty cell).");
  app->add_option("MESH", options->meshPath,
                  "Surface mesh file (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  app->add_option("--descriptor", options->kind, "Descriptor kind")
      ->capture_default_str()
      ->check(CLI::IsMember({"moment", "voxel", "centroid-voxel"}));
  app->add_option("--sampling", options->sampling,
                  "area: the surface clipped exactly to the cells (independent of the tessellation);\n"
                  "vertices: the mesh's vertices, as in the paper")
      ->capture_default_str()
      ->check(CLI::IsMember({"area", "vertices"}));
  app->add_option("--grid", options->grid, "Cells per axis, N")
      ->capture_default_str()
      ->check(CLI::Range(2, core::kMaxGridSize));
  app->add_flag("--json", options->json, "Print one JSON object instead of text");
  addMeshInputFlags(*app, options->input);
  return {app, [options] { return runDescribe(*options); }};
}

}  // namespace shapedb::cli
