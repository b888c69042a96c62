// shapedb haptic: the fixed-rate loop over a scene of surface meshes, augmented from a database as the
// proxy comes near, with a JSON report of its timing.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/statistics.h>
#include <shapedb/haptics/scene.h>
#include <shapedb/io/database.h>
#include <shapedb/io/enrich.h>

#include "commands.h"
#include "material_flags.h"

namespace shapedb::cli {
namespace {

struct HapticCommandOptions {
  MeshLoadFlags load;
  std::string database;
  std::string scene;
  std::string fractureMesh;
  volume::FractureOptions fracture;
  std::string trajectory;
  std::string report;
  std::string descriptor = "centroid-voxel";
  MaterialFlags material;
  haptics::LoopOptions loop;
  double seconds = 10.0;
  double speed = 0.5;
  bool simulate = false;
  bool correct = false;
  bool enrich = false;
  double enrichAbove = 0.0;
};

nlohmann::json percentilesJson(const haptics::Percentiles& p) {
  return {{"p50", p.p50}, {"p99", p.p99}, {"max", p.max}};
}

const char* stateName(haptics::ObjectOutcome::State state) {
  switch (state) {
    case haptics::ObjectOutcome::State::kUntouched:
      return "untouched";
    case haptics::ObjectOutcome::State::kPending:
      return "pending";
    case haptics::ObjectOutcome::State::kReady:
      return "augmented";
    case haptics::ObjectOutcome::State::kFailed:
      return "failed";
  }
  return "?";
}

nlohmann::json reportJson(const HapticCommandOptions& o, const haptics::LoopReport& r,
                          const core::Material& material) {
  nlohmann::json objects = nlohmann::json::array();
  for (const haptics::ObjectOutcome& object : r.objects) {
    nlohmann::json j = {{"name", object.name}, {"state", stateName(object.state)}};
    if (object.state == haptics::ObjectOutcome::State::kReady) {
      j["entry"] = object.source;
      j["augmentation_latency_ms"] = 1e3 * object.augmentationSeconds;
      if (object.upgraded) {
        j["first_entry"] = object.firstSource;
        j["learned_latency_ms"] = 1e3 * object.upgradeSeconds;
      }
      if (!object.upgradeError.empty()) j["learn_error"] = object.upgradeError;
    }
    if (object.state == haptics::ObjectOutcome::State::kFailed) j["error"] = object.error;
    objects.push_back(std::move(j));
  }
  return {{"database", o.database},
          {"scene", o.scene.empty() ? o.fractureMesh : o.scene},
          {"clock", o.simulate ? "simulated" : "steady"},
          {"rate_hz", o.loop.rateHz},
          {"seconds", r.seconds},
          {"ticks", r.ticks},
          {"achieved_rate_hz", r.achievedRateHz},
          {"tick_us", percentilesJson(r.tickMicros)},
          {"tick_start_late_us", percentilesJson(r.startLateMicros)},
          {"deadline_misses", r.deadlineMisses},
          {"realtime_priority", r.realtimePriority},
          {"loop_page_faults", r.pageFaults},
          {"augmentation_latency_ms", percentilesJson(r.augmentationMillis)},
          {"objects_augmented", r.objectsAugmented},
          {"objects_failed", r.objectsFailed},
          {"objects_pending", r.objectsPending},
          {"objects_learned", r.upgrades},
          {"objects_learning", r.upgradesPending},
          {"learned_latency_ms", percentilesJson(r.upgradeMillis)},
          {"contact_ticks", r.contactTicks},
          {"max_force_n", r.maxForce},
          {"material", material.name},
          {"options",
           {{"augmentation_radius_m", o.loop.augmentationRadius},
            {"proxy_radius_m", o.loop.proxyRadius},
            {"stiffness_n_per_m", o.loop.stiffness},
            {"max_force_n", o.loop.maxForce},
            {"workers", o.loop.workers},
            {"burst", o.loop.requestAllAtStart},
            {"descriptor", o.descriptor},
            {"correct", o.correct},
            {"enrich", o.enrich},
            {"enrich_above", o.enrichAbove}}},
          {"objects", std::move(objects)}};
}

// The scene: a folder of meshes, or a mesh broken by --fracture (its fragments where the fracture left
// them: the broken object, in its own frame).
Result<std::vector<haptics::SceneObject>> loadHapticScene(const HapticCommandOptions& o) {
  if (!o.scene.empty()) return haptics::loadScene(o.scene, o.load.options);
  Result<volume::FractureResult> pieces = fractureMeshFile(o.fractureMesh, o.load, o.fracture);
  if (!pieces) return pieces.error();
  std::vector<haptics::SceneObject> scene;
  for (std::size_t i = 0; i < pieces->fragments.size(); ++i)
    scene.push_back({volume::fragmentName(i), std::move(pieces->fragments[i])});
  std::fprintf(stderr, "haptic: %s broken into %zu fragments\n", o.fractureMesh.c_str(), scene.size());
  return scene;
}

// The device: a recorded trajectory, or the default sweep over the scene.
Result<haptics::TrajectoryDevice> hapticDevice(const HapticCommandOptions& o,
                                               const std::vector<haptics::SceneObject>& scene) {
  if (o.trajectory.empty()) return haptics::sweepThrough(scene, o.speed);
  return haptics::TrajectoryDevice::fromCsv(o.trajectory);
}

void printHapticSummary(const HapticCommandOptions& o, const haptics::LoopReport& r) {
  std::printf(
      "ticks %zu at %.1f Hz (asked %.0f), tick µs p50 %.2f p99 %.2f max %.2f, deadline misses %zu%s\n",
      r.ticks, r.achievedRateHz, o.loop.rateHz, r.tickMicros.p50, r.tickMicros.p99, r.tickMicros.max,
      r.deadlineMisses, o.simulate ? " (simulated clock)" : "");
  std::printf("objects %zu: %zu augmented, %zu failed, %zu pending; augmentation ms p50 %.2f p99 %.2f\n",
              r.objects.size(), r.objectsAugmented, r.objectsFailed, r.objectsPending,
              r.augmentationMillis.p50, r.augmentationMillis.p99);
  if (o.loop.requestAllAtStart)
    std::printf("burst: %zu objects requested at the first tick, %s within %.1f ms\n", r.objects.size(),
                r.objectsAugmented == r.objects.size() ? "all augmented" : "not all augmented",
                r.augmentationMillis.max);
  if (o.enrich)
    std::printf(
        "learned: %zu objects swapped to their exact data (ms from entering reach p50 %.0f, max %.0f), "
        "%zu still computing\n",
        r.upgrades, r.upgradeMillis.p50, r.upgradeMillis.max, r.upgradesPending);
  std::printf("contact in %zu ticks, largest force %.3g N; report: %s\n", r.contactTicks, r.maxForce,
              o.report.c_str());
  for (const haptics::ObjectOutcome& object : r.objects)
    if (object.state == haptics::ObjectOutcome::State::kFailed)
      std::fprintf(stderr, "haptic: %s: not augmented: %s\n", object.name.c_str(), object.error.c_str());
    else if (!object.upgradeError.empty())
      std::fprintf(stderr, "haptic: %s: not learned: %s\n", object.name.c_str(), object.upgradeError.c_str());
}

int runHaptic(const HapticCommandOptions& o, const CLI::App& app) {
  const std::optional<core::Material> material = resolveMaterial(o.material, app);
  if (!material) return kExitUsage;
  if (o.scene.empty() == o.fractureMesh.empty()) {
    printError("give a SCENE_DIR or --fracture MESH --pieces N, not both");
    return kExitUsage;
  }
  Result<std::vector<haptics::SceneObject>> scene = loadHapticScene(o);
  if (!scene) {
    printError(scene.error().message);
    return kExitInputError;
  }
  io::Database::OpenOptions open;
  open.learn = o.enrich;
  open.descriptors = {*core::parseDescriptorKind(o.descriptor)};
  auto db = io::Database::open(o.database, open);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }
  Result<haptics::TrajectoryDevice> device = hapticDevice(o, *scene);
  if (!device) {
    printError(device.error().message);
    return kExitInputError;
  }

  io::QueryOptions query;
  query.descriptor = *core::parseDescriptorKind(o.descriptor);
  query.material = *material;
  query.fidelity = false;  // the loop needs the data, not the report; it would double the latency
  query.correct = o.correct;
  // Learning: one background computation at a time, beside the loop's own threads.
  std::optional<io::Enricher> enricher;
  if (o.enrich) enricher.emplace(*db);
  auto loop =
      haptics::HapticLoop::create(*scene, *device,
                                  enricher ? haptics::learningAugmenter(*db, *enricher, query, o.enrichAbove)
                                           : haptics::databaseAugmenter(*db, query),
                                  o.loop);
  if (!loop) {
    printError(loop.error().message);
    return kExitUsage;
  }
  std::fprintf(stderr, "haptic: %zu objects, %.0f Hz for %.3g s (%s clock), %d worker%s...\n", scene->size(),
               o.loop.rateHz, o.seconds, o.simulate ? "simulated" : "steady", o.loop.workers,
               o.loop.workers == 1 ? "" : "s");
  const haptics::LoopReport r = o.simulate ? (*loop)->simulate(o.seconds) : (*loop)->run(o.seconds);
  if (enricher && enricher->pending() > 0)
    std::fprintf(
        stderr,
        "haptic: %zu objects still being learned: the one under way is finished and kept, the others "
        "are left for another run (or shapedb enrich)\n",
        enricher->pending());
  std::ofstream out(o.report);
  out << reportJson(o, r, *material).dump(2) << '\n';
  if (!out) {
    printError(o.report + ": cannot write the report");
    return kExitInputError;
  }
  printHapticSummary(o, r);
  return kExitOk;
}

}  // namespace

Command addHapticCommand(CLI::App& parent) {
  auto o = std::make_shared<HapticCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "haptic",
      "Run the fixed-rate haptic loop over a scene of surface meshes (a directory, or the fragments of a\n"
      "mesh broken with --fracture): a proxy sphere moves through the scene (a CSV trajectory, or by\n"
      "default a sweep through it); objects it comes near are given physical data from the database by\n"
      "worker threads (query, adapt, link) while the loop keeps its rate; objects it touches push back\n"
      "through their collision compound and vibrate through their modes. Writes a JSON report: achieved\n"
      "rate, tick time percentiles, deadline misses, augmentation latency, per-object outcome. Objects that\n"
      "cannot be augmented (say, open meshes) are reported, not fatal.");
  app->add_option("DB", o->database, "Database file (shapedb build)")->required();
  app->add_option(
      "SCENE_DIR", o->scene,
      "Directory of surface meshes (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae), each an object in "
      "world coordinates, "
      "metres");
  addFractureSourceFlags(
      *app, o->fractureMesh, o->fracture,
      "Instead of SCENE_DIR: break this closed mesh into fragments (as shapedb fracture) and "
      "use them, in place, as the scene");
  addMeshLoadFlags(*app, o->load);
  app->add_option("--report", o->report, "JSON report file")->required();
  app->add_option("--rate", o->loop.rateHz, "Loop rate, Hz")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1e5));
  app->add_option("--seconds", o->seconds, "How long to run")
      ->capture_default_str()
      ->check(CLI::Range(1e-3, 1e5));
  app->add_option("--trajectory", o->trajectory,
                  "Proxy path as CSV lines 't,x,y,z' (seconds, metres), linearly interpolated")
      ->check(CLI::ExistingFile);
  app->add_option("--speed", o->speed,
                  "Without --trajectory: the proxy sweeps the scene row by row at this speed, m/s")
      ->capture_default_str()
      ->check(CLI::Range(1e-6, 1e3));
  app->add_option("--radius", o->loop.augmentationRadius,
                  "Augmentation radius: objects this close to the proxy get physical data, m")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1e6));
  app->add_option("--proxy-radius", o->loop.proxyRadius, "Radius of the proxy sphere, m")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 1e6));
  app->add_option("--stiffness", o->loop.stiffness, "Contact stiffness, N/m")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 1e12));
  app->add_option("--max-force", o->loop.maxForce, "The device's force limit, N")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 1e6));
  app->add_option("--workers", o->loop.workers, "Augmentation threads")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app->add_flag("--burst", o->loop.requestAllAtStart,
                "A fracture event: request every object at the first tick, wherever the proxy is (as a\n"
                "fracture's fragments all need data at once); the report's augmentation max is the time to\n"
                "all augmented. Use --workers to spread the burst over cores");
  app->add_option("--descriptor", o->descriptor, "Descriptor to match by")
      ->capture_default_str()
      ->check(CLI::IsMember({"moment", "voxel", "centroid-voxel"}));
  addMaterialFlags(*app, o->material);
  app->add_flag("--correct", o->correct,
                "Augment with the geometry correction (shapedb query --correct): modes of the best entry's\n"
                "tets morphed onto each object, tens of ms more per object on the augmentation workers,\n"
                "never in the loop's tick");
  app->add_flag("--enrich", o->enrich,
                "Learn each object touched: its exact data computed in the background (shapedb enrich; one\n"
                "at a time), added to DB (which must be writable), and swapped into the loop between two\n"
                "ticks once ready; the report gives each object's first entry and the latency to its own");
  app->add_option("--enrich-above", o->enrichAbove,
                  "With --enrich: learn only the objects whose answer's predicted first-frequency error is\n"
                  "above this fraction (the fidelity report is then computed for each); 0: all")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0))
      ->needs(app->get_option("--enrich"));
  app->add_flag(
      "--simulate", o->simulate,
      "Simulated clock: deterministic, as fast as the machine goes, augmentation served after 20 ms "
      "of loop time");
  return {app, [o, app] { return runHaptic(*o, *app); }};
}

}  // namespace shapedb::cli
