#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/self_intersection.h>
#include <shapedb/core/topology.h>
#include <shapedb/io/mesh_io.h>

#include "commands.h"
#include "format.h"
#include "mesh_input.h"

namespace shapedb::cli {
namespace {

struct InspectOptions {
  std::string meshPath;
  bool json = false;
  MeshInputOptions input;
};

/// The solids and cavities of a closed, oriented surface's shells; nothing for any other.
std::optional<core::ShellCount> shellCount(const io::LoadedMesh& loaded) {
  const core::TopologyReport& t = loaded.topology;
  if (!t.isClosed() || !t.isConsistentlyOriented()) return std::nullopt;
  return core::countShells(core::findShells(loaded.mesh));
}

nlohmann::json topologyJson(const io::LoadedMesh& loaded,
                            const std::vector<core::TriangleCrossing>& crossings) {
  const core::TopologyReport& t = loaded.topology;
  const std::optional<core::ShellCount> shells = shellCount(loaded);
  nlohmann::json firstCrossing = nullptr;
  if (!crossings.empty())
    firstCrossing = {{"triangles", {crossings.front().first, crossings.front().second}},
                     {"point", toJson(crossings.front().point)}};
  return {{"vertices", t.vertexCount},
          {"unreferenced_vertices", t.unreferencedVertices},
          {"triangles", t.triangleCount},
          {"edges", t.edgeCount},
          {"boundary_edges", t.boundaryEdges},
          {"non_manifold_edges", t.nonManifoldEdges},
          {"inconsistent_edges", t.inconsistentEdges},
          {"components", t.components},
          {"solids", shells ? nlohmann::json(shells->solids) : nlohmann::json(nullptr)},
          {"cavities", shells ? nlohmann::json(shells->cavities) : nlohmann::json(nullptr)},
          {"euler_characteristic", t.eulerCharacteristic()},
          {"is_closed", t.isClosed()},
          {"is_consistently_oriented", t.isConsistentlyOriented()},
          {"zero_area_faces", loaded.defects.zeroAreaFaces},
          {"faces_dropped", loaded.facesDropped},
          {"polygons_triangulated", loaded.polygonsTriangulated},
          {"welded_vertices", loaded.verticesWelded},
          {"specks_dropped", loaded.specksDropped},
          {"crossing_triangle_pairs", crossings.size()},
          {"first_crossing", firstCrossing}};
}

nlohmann::json reportJson(const InspectOptions& options, const io::LoadedMesh& loaded,
                          const std::vector<core::TriangleCrossing>& crossings,
                          const core::MassProperties& mp, const core::Normalization& n) {
  return {{"file", options.meshPath},
          {"format", loaded.format},
          {"scale", loaded.scale},
          {"topology", topologyJson(loaded, crossings)},
          {"density", mp.density},
          {"mass", mp.mass},
          {"volume", mp.volume},
          {"area", mp.area},
          {"center_of_mass", toJson(mp.centerOfMass)},
          {"inertia", toJson(mp.inertia)},
          {"principal_moments", toJson(n.principalMoments)},
          {"principal_axes", toJson(core::Mat3(n.principalAxes.transpose()))},
          {"transform", toJson(n.canonicalFromMesh)},
          {"transform_inverse", toJson(n.meshFromCanonical)},
          {"scale", n.scale},
          {"canonical_moments", toJson(n.canonicalMoments)},
          {"degeneracy",
           {{"axes", core::toString(n.degeneracy)},
            {"moment_gaps", n.momentGaps},
            {"conditioning", n.conditioning()},
            {"skewness", n.skewness},
            {"sign_ambiguous", n.signAmbiguous},
            {"plane_symmetry", n.planeSymmetry},
            {"distinct_axis_ambiguous", n.distinctAxisAmbiguous}}},
          {"approximate", mp.isApproximate},
          {"flipped", mp.wasFlipped || loaded.flippedInsideOut}};
}

void printText(const InspectOptions& options, const io::LoadedMesh& loaded,
               const std::vector<core::TriangleCrossing>& crossings, const core::MassProperties& mp,
               const core::Normalization& n) {
  const core::TopologyReport& t = loaded.topology;
  std::printf("%s (%s): %zu vertices, %zu triangles\n", options.meshPath.c_str(), loaded.format.c_str(),
              t.vertexCount, t.triangleCount);
  std::printf("topology: %s, %s, %zu component%s, Euler characteristic %ld\n",
              t.isClosed() ? "closed" : "OPEN",
              t.isConsistentlyOriented() ? "consistently oriented" : "INCONSISTENT", t.components,
              t.components == 1 ? "" : "s", t.eulerCharacteristic());
  if (const std::optional<core::ShellCount> shells = shellCount(loaded); shells && t.components > 1)
    std::printf("  shells: %zu solid%s, %zu cavit%s (inner shells wound inward: hollow there)\n",
                shells->solids, shells->solids == 1 ? "" : "s", shells->cavities,
                shells->cavities == 1 ? "y" : "ies");
  std::printf("  boundary edges %zu, non-manifold edges %zu, inconsistent edges %zu, zero-area faces %zu\n",
              t.boundaryEdges, t.nonManifoldEdges, t.inconsistentEdges, loaded.defects.zeroAreaFaces);
  if (crossings.empty()) {
    std::printf("  crossing triangle pairs 0\n");
  } else {
    const core::TriangleCrossing& c = crossings.front();
    std::printf(
        "  CROSSING triangle pairs %zu (triangles %u and %u at %s): the surface passes through itself;\n"
        "  a tet mesh of it (add, enrich, bench's truth) needs --repair\n",
        crossings.size(), c.first, c.second, toText(c.point).c_str());
  }
  if (mp.isApproximate)
    std::printf("APPROXIMATE: vertex point masses (paper §4.1); the surface does not bound a solid\n");
  if (mp.wasFlipped || loaded.flippedInsideOut)
    std::printf("note: the mesh was inside out and has been flipped\n");
  std::printf("volume           %.9g m³\n", mp.volume);
  std::printf("area             %.9g m²\n", mp.area);
  std::printf("density          %.9g kg/m³, mass %.9g kg\n", mp.density, mp.mass);
  std::printf("center of mass   %s m\n", toText(mp.centerOfMass).c_str());
  std::printf("inertia about the centre of mass, kg m²:\n%s", toText(mp.inertia, "  ").c_str());
  std::printf("principal moments %s kg m²\n", toText(n.principalMoments).c_str());
  std::printf("principal axes (rows: x, y, z in the mesh frame):\n%s",
              toText(core::Mat3(n.principalAxes.transpose()), "  ").c_str());
  std::printf("T = canonicalFromMesh (volume 1, centre of mass at 0, principal axes on x, y, z):\n%s",
              toText(n.canonicalFromMesh, "  ").c_str());
  std::printf("axes: degeneracy %s (moment gaps %.3g, %.3g); sign of x %s (skewness %.3g), of y %s (%.3g)\n",
              core::toString(n.degeneracy), n.momentGaps[0], n.momentGaps[1],
              n.signAmbiguous[0] ? "AMBIGUOUS" : "decided", n.skewness[0],
              n.signAmbiguous[1] ? "AMBIGUOUS" : "decided", n.skewness[1]);
}

int runInspect(const InspectOptions& options) {
  std::optional<MeshInput> input = loadMeshInput(options.meshPath, options.input);
  if (!input) return kExitInputError;
  const io::LoadedMesh* loaded = &input->loaded;
  const core::MassProperties* mp = &input->massProperties;
  const core::Normalization* n = &input->normalization;
  const std::vector<core::TriangleCrossing> crossings = core::findSelfIntersections(loaded->mesh);
  if (options.json)
    std::printf("%s\n", reportJson(options, *loaded, crossings, *mp, *n).dump(2).c_str());
  else
    printText(options, *loaded, crossings, *mp, *n);
  return kExitOk;
}

}  // namespace

Command addInspectCommand(CLI::App& parent) {
  auto options = std::make_shared<InspectOptions>();
  CLI::App* app = parent.add_subcommand(
      "inspect",
      "Load a surface mesh and print its topology (with the pairs of triangles that cross: a surface\n"
      "that passes through itself), exact mass properties (volume, area, centre of mass,\n"
      "inertia), principal moments and axes, and the normalizing transform T = canonicalFromMesh\n"
      "(volume 1, centre of mass at the origin, principal axes on x, y, z), with flags for axes that\n"
      "the shape leaves undetermined. Formats: OBJ, PLY, OFF, STL, glTF (.gltf, .glb), FBX, COLLADA (.dae).");
  app->add_option("MESH", options->meshPath,
                  "Surface mesh file (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  app->add_flag("--json", options->json, "Print one JSON object with stable field names instead of text");
  addMeshInputFlags(*app, options->input);
  return {app, [options] { return runInspect(*options); }};
}

}  // namespace shapedb::cli
