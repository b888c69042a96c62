// shapedb drop: the rigid-body scenario. Meshes (or the fragments of a fractured one) get their mass
// properties and collision compounds from a database query and fall on a floor in Bullet; the summary
// says where they came to rest, when, and how far anything went into the floor.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/fracture.h>
#ifdef SHAPEDB_HAVE_BULLET
#include <shapedb/haptics/drop_scene.h>
#endif

#include "commands.h"
#include "format.h"
#include "material_flags.h"

namespace shapedb::cli {
namespace {

struct DropCommandOptions {
  MeshLoadFlags load;
  std::string database;
  std::vector<std::string> meshes;
  std::string fractureMesh;
  volume::FractureOptions fracture;
  MaterialFlags material;
  double height = 0.3;
  double seconds = 3.0;
  double rate = 240.0;
  double friction = 0.6;
  double restitution = 0.2;
  std::string frames;
  double frameRate = 30.0;
  bool json = false;
};

#ifdef SHAPEDB_HAVE_BULLET

/// The fragments of --fracture MESH, or the MESH files given.
Result<haptics::DropScene> loadDropScene(const DropCommandOptions& o) {
  haptics::DropScene scene;
  if (!o.fractureMesh.empty()) {
    Result<volume::FractureResult> pieces = fractureMeshFile(o.fractureMesh, o.load, o.fracture);
    if (!pieces) return pieces.error();
    for (std::size_t i = 0; i < pieces->fragments.size(); ++i) {
      scene.meshes.push_back(std::move(pieces->fragments[i]));
      scene.names.push_back(volume::fragmentName(i));
    }
    return scene;
  }
  for (const std::string& file : o.meshes) {
    Result<io::LoadedMesh> loaded = loadMeshFile(file, o.load);
    if (!loaded) return loaded.error();
    scene.meshes.push_back(std::move(loaded->mesh));
    scene.names.push_back(std::filesystem::path(file).filename().string());
  }
  return scene;
}

void printDropJson(const DropCommandOptions& o, const haptics::DropScene& scene,
                   const haptics::DropSceneReport& d) {
  const haptics::DropReport& report = d.report;
  nlohmann::json out = {{"database", o.database},
                        {"bodies", nlohmann::json::array()},
                        {"skipped", nlohmann::json::array()},
                        {"at_rest", report.atRest},
                        {"seconds", o.seconds},
                        {"time_step", d.options.timeStep},
                        {"lift", d.options.lift},
                        {"deepest_penetration", -d.deepest},
                        {"deepest_penetration_end", -d.deepestAtEnd},
                        {"energy_start", d.energyStart},
                        {"energy_end", d.energyEnd},
                        {"kinetic_energy_end", report.kineticEnergy.back()},
                        {"frames", report.frames.size()}};
  for (const haptics::SkippedMesh& s : d.skipped)
    out["skipped"].push_back(s.name + ": " + s.error.message);
  for (std::size_t b = 0; b < d.bodies.size(); ++b) {
    const haptics::BodyOutcome& outcome = report.bodies[b];
    const core::Vec3 com = d.bodies[b].massProperties.centerOfMass;
    const core::Vec3 finalCom =
        outcome.finalPose.topLeftCorner<3, 3>() * com + outcome.finalPose.topRightCorner<3, 1>();
    out["bodies"].push_back(
        {{"name", scene.names[d.source[b]]},
         {"mass", d.bodies[b].massProperties.mass},
         {"shapes", d.bodies[b].collision.shapes.size()},
         {"start_center_of_mass", toJson(core::Vec3(com + core::Vec3(0, 0, d.options.lift)))},
         {"final_center_of_mass", toJson(finalCom)},
         {"rest_time", outcome.restTime},
         {"lowest_point", outcome.lowestPoint},
         {"final_lowest_point", outcome.finalLowestPoint}});
  }
  std::printf("%s\n", out.dump(2).c_str());
}

void printDropText(const DropCommandOptions& o, const core::Material& material,
                   const haptics::DropSceneReport& d) {
  const std::size_t n = d.bodies.size();
  std::printf("%zu bodies (%.4g kg in all, %s) dropped from %.3g m for %.3g s at %.0f Hz in Bullet\n", n,
              d.totalMass, material.name.c_str(), o.height, o.seconds, o.rate);
  if (d.report.atRest == n)
    std::printf("at rest: all %zu, the last from %.2f s\n", n, d.lastRest);
  else
    std::printf("at rest: %zu of %zu at the end\n", d.report.atRest, n);
  std::printf("energy: %.4g J at the start, %.4g J at the end (kinetic %.3g J)\n", d.energyStart, d.energyEnd,
              d.report.kineticEnergy.back());
  std::printf("deepest into the floor: %.1f mm at an impact, %.2f mm at the end\n", -1000.0 * d.deepest,
              -1000.0 * d.deepestAtEnd);
  if (!o.frames.empty()) std::printf("frames: %zu PNGs in %s\n", d.report.frames.size(), o.frames.c_str());
  for (const haptics::SkippedMesh& s : d.skipped)
    std::printf("skipped %s: %s%s\n", s.name.c_str(), s.error.message.c_str(), flagHint(s.error).c_str());
}

int runDrop(const DropCommandOptions& o, const CLI::App& app) {
  const std::optional<core::Material> material = resolveMaterial(o.material, app);
  if (!material) return kExitUsage;
  Result<haptics::DropScene> scene = loadDropScene(o);
  if (!scene) {
    printError(scene.error().message);
    return kExitInputError;
  }
  io::Database::OpenOptions open;
  open.descriptors = {io::QueryOptions{}.descriptor};  // the drop queries by the default descriptor
  auto db = io::Database::open(o.database, open);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }
  haptics::DropSceneOptions options;
  options.material = *material;
  options.height = o.height;
  options.drop.seconds = o.seconds;
  options.drop.timeStep = 1.0 / o.rate;
  options.drop.friction = o.friction;
  options.drop.restitution = o.restitution;
  if (!o.frames.empty())
    options.drop.recordEvery = std::max<std::size_t>(1, static_cast<std::size_t>(o.rate / o.frameRate));
  Result<haptics::DropSceneReport> dropped = haptics::dropOnFloor(*db, *scene, options);
  if (!dropped) {
    printError(dropped.error().message + flagHint(dropped.error()));
    return kExitInputError;
  }
  if (!o.frames.empty())
    if (Status st = haptics::saveDropFrames(*scene, *dropped, o.height, o.frames); !st) {
      printError(st.error().message);
      return kExitInputError;
    }
  if (o.json)
    printDropJson(o, *scene, *dropped);
  else
    printDropText(o, *material, *dropped);
  return kExitOk;
}

#else

int runDrop(const DropCommandOptions&, const CLI::App&) {
  printError("this shapedb was built without Bullet (install libbullet-dev and rebuild)");
  return kExitUsage;
}

#endif

}  // namespace

Command addDropCommand(CLI::App& parent) {
  auto o = std::make_shared<DropCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "drop",
      "The rigid-body scenario: each mesh (or each fragment of --fracture MESH) gets its mass properties\n"
      "and collision compound (spheres, boxes, capsules) from its best database match, adapted to its size\n"
      "and material; all fall together onto a floor in Bullet, from where they are raised to --height.\n"
      "Prints where they came to rest, when, the energy, and the deepest penetration of the floor;\n"
      "--frames writes a PNG per frame. Needs a shapedb built with Bullet (libbullet-dev).");
  app->add_option("DB", o->database, "Database file (shapedb build)")->required();
  app->add_option("MESH", o->meshes,
                  "Closed meshes to drop (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)");
  addFractureSourceFlags(*app, o->fractureMesh, o->fracture,
                         "Drop the fragments of this closed mesh instead");
  addMeshLoadFlags(*app, o->load);
  addMaterialFlags(*app, o->material);
  app->add_option("--height", o->height, "Height of the lowest point at the start (m)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  app->add_option("--seconds", o->seconds, "Simulated time (s)")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 600.0));
  app->add_option("--rate", o->rate, "Simulation steps per second")
      ->capture_default_str()
      ->check(CLI::Range(30.0, 10000.0));
  app->add_option("--friction", o->friction, "Friction coefficient of every contact")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  app->add_option("--restitution", o->restitution, "Restitution of every contact")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  CLI::Option* frames =
      app->add_option("--frames", o->frames, "Write frame-0000.png, ... (a view from the front) into DIR");
  app->add_option("--frame-rate", o->frameRate, "With --frames: frames per simulated second")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0))
      ->needs(frames);
  app->add_flag(
      "--json", o->json,
      "Print one JSON object: {bodies: [{name, mass, shapes, start_center_of_mass, "
      "final_center_of_mass,\nrest_time, lowest_point}], at_rest, deepest_penetration, energy_start, "
      "energy_end, ...}");
  app->callback([o] {
    if (o->fractureMesh.empty() == o->meshes.empty())
      throw CLI::ValidationError("give either MESH files or --fracture MESH");
  });
  return {app, [o, app] { return runDrop(*o, *app); }};
}

}  // namespace shapedb::cli
