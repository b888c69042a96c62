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

#include <shapedb/core/primitives.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/io/render.h>
#include <shapedb/volume/fracture.h>
#ifdef SHAPEDB_HAVE_BULLET
#include <shapedb/haptics/rigid_drop.h>
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

/// The surfaces moved by each body's pose, with a floor and a backdrop so that every frame has the same
/// framing (the renderer centres on the bounding box).
Status saveFrame(const std::vector<core::TriangleMesh>& surfaces, const std::vector<core::Mat4>& poses,
                 const core::TriangleMesh& stage, const std::filesystem::path& path) {
  std::vector<core::TriangleMesh> moved;
  moved.reserve(surfaces.size());
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    moved.push_back(core::transformed(surfaces[i], poses[i]));
  io::Panel panel;
  panel.meshes.push_back(&stage);
  panel.colors.push_back({200, 200, 190});
  for (std::size_t i = 0; i < moved.size(); ++i) {
    panel.meshes.push_back(&moved[i]);
    panel.colors.push_back({static_cast<std::uint8_t>(90 + (i * 67) % 150),
                            static_cast<std::uint8_t>(80 + (i * 41) % 120),
                            static_cast<std::uint8_t>(200 - (i * 29) % 120)});
  }
  // Looking along +y, a little from above: right = x, up ≈ z.
  const double tilt = 0.35;
  core::Mat3 view;
  view.row(0) = core::Vec3(1, 0, 0);
  view.row(1) = core::Vec3(0, std::sin(tilt), std::cos(tilt));
  view.row(2) = core::Vec3(0, -std::cos(tilt), std::sin(tilt));
  const io::Panel panels[] = {panel};
  return io::savePng(io::renderPanels(panels, view, 480), path);
}

int runDrop(const DropCommandOptions& o, const CLI::App& app) {
  const std::optional<core::Material> material = resolveMaterial(o.material, app);
  if (!material) return kExitUsage;
  // The meshes: the fragments of one, or the files given.
  std::vector<core::TriangleMesh> meshes;
  std::vector<std::string> names;
  if (!o.fractureMesh.empty()) {
    Result<volume::FractureResult> pieces = fractureMeshFile(o.fractureMesh, o.load, o.fracture);
    if (!pieces) {
      printError(pieces.error().message);
      return kExitInputError;
    }
    for (std::size_t i = 0; i < pieces->fragments.size(); ++i) {
      meshes.push_back(std::move(pieces->fragments[i]));
      names.push_back(volume::fragmentName(i));
    }
  } else {
    for (const std::string& file : o.meshes) {
      Result<io::LoadedMesh> loaded = loadMeshFile(file, o.load);
      if (!loaded) {
        printError(loaded.error().message);
        return kExitInputError;
      }
      meshes.push_back(std::move(loaded->mesh));
      names.push_back(std::filesystem::path(file).filename().string());
    }
  }
  auto db = io::Database::open(o.database);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }

  // Each body's mass properties and compound from its best match, adapted to its size and material.
  io::QueryOptions query;
  query.material = *material;
  query.link = false;
  query.fidelity = false;
  std::vector<haptics::RigidBody> bodies;
  std::vector<std::size_t> source;  // mesh index of each body
  std::vector<std::string> skipped;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    Result<io::QueryResult> r = db->query(meshes[i], query);
    if (!r || !r->physics) {
      skipped.push_back(names[i] + ": " + (r ? std::string("no physical data") : r.error().message));
      continue;
    }
    bodies.push_back({r->physics->massProperties, r->physics->collision});
    source.push_back(i);
  }
  if (bodies.empty()) {
    printError("no mesh could be given physical data");
    for (const std::string& s : skipped)
      printError(s);
    return kExitInputError;
  }

  // Everything raised together so that its lowest collision point is at --height.
  double lowest = std::numeric_limits<double>::infinity();
  for (const haptics::RigidBody& b : bodies)
    for (const core::CollisionShape& s : b.collision.shapes)
      lowest = std::min(lowest, haptics::lowestPoint(s));
  haptics::DropOptions options;
  options.lift = o.height - lowest;
  options.seconds = o.seconds;
  options.timeStep = 1.0 / o.rate;
  options.friction = o.friction;
  options.restitution = o.restitution;
  if (!o.frames.empty())
    options.recordEvery = std::max<std::size_t>(1, static_cast<std::size_t>(o.rate / o.frameRate));
  Result<haptics::DropReport> report = haptics::simulateDrop(bodies, options);
  if (!report) {
    printError(report.error().message);
    return kExitInputError;
  }

  if (!o.frames.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.frames, ec);
    if (ec) {
      printError(o.frames + ": " + ec.message());
      return kExitInputError;
    }
    // A floor under the start's footprint and a backdrop as high as the start: a fixed framing.
    core::Vec3 lo = core::Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t b = 0; b < bodies.size(); ++b)
      for (const core::Vec3& p : meshes[source[b]].vertices) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    const core::Vec3 size = hi - lo;
    const double margin = 0.6 * std::max(size.x(), size.y());
    core::TriangleMesh stage = core::makeBox({size.x() + 2 * margin, size.y() + 2 * margin, 0.002});
    const core::Vec3 middle = 0.5 * (lo + hi);
    for (core::Vec3& p : stage.vertices)
      p += core::Vec3(middle.x(), middle.y(), -0.001);
    core::TriangleMesh backdrop = core::makeBox({size.x() + 2 * margin, 0.002, o.height + size.z() + margin});
    for (core::Vec3& p : backdrop.vertices)
      p += core::Vec3(middle.x(), hi.y() + margin, 0.5 * (o.height + size.z() + margin));
    core::append(stage, backdrop);
    std::vector<core::TriangleMesh> surfaces;
    for (std::size_t b = 0; b < bodies.size(); ++b)
      surfaces.push_back(meshes[source[b]]);
    for (std::size_t f = 0; f < report->frames.size(); ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "frame-%04zu.png", f);
      if (Status st = saveFrame(surfaces, report->frames[f], stage, std::filesystem::path(o.frames) / name);
          !st) {
        printError(st.error().message);
        return kExitInputError;
      }
    }
  }

  double deepest = 0.0, deepestAtEnd = 0.0, lastRest = 0.0, totalMass = 0.0;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    deepest = std::min(deepest, report->bodies[b].lowestPoint);
    deepestAtEnd = std::min(deepestAtEnd, report->bodies[b].finalLowestPoint);
    lastRest = std::max(lastRest, report->bodies[b].restTime);
    totalMass += bodies[b].massProperties.mass;
  }
  const double startEnergy = report->kineticEnergy.front() + report->potentialEnergy.front();
  const double endEnergy = report->kineticEnergy.back() + report->potentialEnergy.back();
  if (o.json) {
    nlohmann::json out = {{"database", o.database},
                          {"bodies", nlohmann::json::array()},
                          {"skipped", skipped},
                          {"at_rest", report->atRest},
                          {"seconds", o.seconds},
                          {"time_step", options.timeStep},
                          {"lift", options.lift},
                          {"deepest_penetration", -deepest},
                          {"deepest_penetration_end", -deepestAtEnd},
                          {"energy_start", startEnergy},
                          {"energy_end", endEnergy},
                          {"kinetic_energy_end", report->kineticEnergy.back()},
                          {"frames", report->frames.size()}};
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      const haptics::BodyOutcome& outcome = report->bodies[b];
      const core::Vec3 com = bodies[b].massProperties.centerOfMass;
      const core::Vec3 finalCom =
          outcome.finalPose.topLeftCorner<3, 3>() * com + outcome.finalPose.topRightCorner<3, 1>();
      out["bodies"].push_back(
          {{"name", names[source[b]]},
           {"mass", bodies[b].massProperties.mass},
           {"shapes", bodies[b].collision.shapes.size()},
           {"start_center_of_mass", toJson(core::Vec3(com + core::Vec3(0, 0, options.lift)))},
           {"final_center_of_mass", toJson(finalCom)},
           {"rest_time", outcome.restTime},
           {"lowest_point", outcome.lowestPoint},
           {"final_lowest_point", outcome.finalLowestPoint}});
    }
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("%zu bodies (%.4g kg in all, %s) dropped from %.3g m for %.3g s at %.0f Hz in Bullet\n",
                bodies.size(), totalMass, material->name.c_str(), o.height, o.seconds, o.rate);
    if (report->atRest == bodies.size())
      std::printf("at rest: all %zu, the last from %.2f s\n", bodies.size(), lastRest);
    else
      std::printf("at rest: %zu of %zu at the end\n", report->atRest, bodies.size());
    std::printf("energy: %.4g J at the start, %.4g J at the end (kinetic %.3g J)\n", startEnergy, endEnergy,
                report->kineticEnergy.back());
    std::printf("deepest into the floor: %.1f mm at an impact, %.2f mm at the end\n", -1000.0 * deepest,
                -1000.0 * deepestAtEnd);
    if (!o.frames.empty()) std::printf("frames: %zu PNGs in %s\n", report->frames.size(), o.frames.c_str());
    for (const std::string& s : skipped)
      std::printf("skipped %s\n", s.c_str());
  }
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
  app->add_option("MESH", o->meshes, "Closed meshes to drop (.obj, .ply, .off, .stl)");
  app->add_option("--fracture", o->fractureMesh, "Drop the fragments of this closed mesh instead");
  app->add_option("--pieces", o->fracture.pieces, "With --fracture: Voronoi seeds")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  addFractureFlags(*app, o->fracture);
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
  app->add_option("--frames", o->frames, "Write frame-0000.png, ... (a view from the front) into DIR");
  app->add_option("--frame-rate", o->frameRate, "Frames per simulated second, with --frames")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
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
