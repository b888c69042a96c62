// The haptic loop: a scene of fragments, the proxy sweeping through it, the loop at 1 kHz in
// real time for 10 s while a worker augments the fragments it comes near from the database.
//   build/release/bin/haptic_bench [DB] [--objects N] [--seconds S] [--rate HZ] [--workers W]
//                                  [--speed M_PER_S] [--scene-out DIR]
//   (DB default: build/demo.db; --scene-out writes the scene's meshes, for `shapedb haptic DB DIR`)
// Targets on the 2-core reference machine: 0 deadline misses in 10 s at 1 kHz with augmentation running
// on the other core; tick compute p99 <= 100 us. An empty loop (no scene, no worker) runs first for as
// long, so that misses the platform causes on its own are told apart from the loop's.
// The fragments are the database's own "shard" family (random convex polyhedra, the shapes fracture
// makes) at new seeds, 3-8 cm across, turned at random and laid on a floor in a grid 12 cm apart; the
// proxy (5 mm radius) passes along the rows one after the other at half the fragments' height, at a hand's
// speed (0.5 m/s: about 40 fragments augmented in 10 s; faster sweeps queue more work for the worker).
// A plain program: it reports the loop's own percentiles.

#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <shapedb/haptics/scene.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/families.h>

namespace {

using shapedb::core::Vec3;
namespace haptics = shapedb::haptics;

std::vector<haptics::SceneObject> makeScene(int count, int columns, double spacing, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<haptics::SceneObject> objects;
  for (int i = 0; i < count; ++i) {
    // Seeds far past any database's sweep: shapes the database has not seen.
    const auto spec =
        shapedb::volume::familySpec(shapedb::volume::Family::kShard, 100000u + static_cast<std::uint32_t>(i));
    shapedb::core::TriangleMesh mesh = *shapedb::volume::makeFamilyShape(spec);
    const Eigen::Quaterniond q(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    const shapedb::core::Bounds raw = shapedb::core::computeBounds(mesh);
    const double size = 0.03 + 0.05 * u(rng);
    const double scale = size / (raw.max - raw.min).maxCoeff();
    for (Vec3& v : mesh.vertices)
      v = scale * (q.normalized() * v);
    const shapedb::core::Bounds box = shapedb::core::computeBounds(mesh);
    const Vec3 at((i % columns) * spacing, (i / columns) * spacing, 0.0);
    const Vec3 shift =
        at - Vec3(0.5 * (box.min.x() + box.max.x()), 0.5 * (box.min.y() + box.max.y()), box.min.z());
    for (Vec3& v : mesh.vertices)
      v += shift;
    char name[32];
    std::snprintf(name, sizeof name, "fragment-%03d.ply", i);
    objects.push_back({name, std::move(mesh)});
  }
  return objects;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dbPath = "build/demo.db", sceneOut;
  int count = 200, workers = 1;
  double seconds = 10.0, rate = 1000.0, speed = 0.5;
  for (int i = 1; i < argc; ++i) {
    const auto next = [&] { return i + 1 < argc ? argv[++i] : ""; };
    if (!std::strcmp(argv[i], "--objects"))
      count = std::atoi(next());
    else if (!std::strcmp(argv[i], "--seconds"))
      seconds = std::atof(next());
    else if (!std::strcmp(argv[i], "--rate"))
      rate = std::atof(next());
    else if (!std::strcmp(argv[i], "--workers"))
      workers = std::atoi(next());
    else if (!std::strcmp(argv[i], "--speed"))
      speed = std::atof(next());
    else if (!std::strcmp(argv[i], "--scene-out"))
      sceneOut = next();
    else if (argv[i][0] != '-')
      dbPath = argv[i];
    else {
      std::fprintf(stderr, "haptic_bench: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  if (count < 1 || seconds <= 0.0 || rate <= 0.0 || workers < 1 || speed <= 0.0) {
    std::fprintf(stderr,
                 "haptic_bench: --objects, --seconds, --rate, --workers and --speed must be positive\n");
    return 2;
  }
  auto db = shapedb::io::Database::open(dbPath);
  if (!db) {
    std::fprintf(stderr, "haptic_bench: %s\n", db.error().message.c_str());
    return 1;
  }
  std::mt19937_64 rng(2026);
  const int columns = 15;
  const double spacing = 0.12;
  const std::vector<haptics::SceneObject> objects = makeScene(count, columns, spacing, rng);
  if (!sceneOut.empty()) {
    std::filesystem::create_directories(sceneOut);
    for (const haptics::SceneObject& o : objects)
      if (auto st = shapedb::io::saveMesh(o.mesh, std::filesystem::path(sceneOut) / o.name); !st) {
        std::fprintf(stderr, "haptic_bench: %s\n", st.error().message.c_str());
        return 1;
      }
  }

  // Along every row at 2 cm, the fragments' middle height.
  const int rows = (count + columns - 1) / columns;
  haptics::TrajectoryDevice device = haptics::TrajectoryDevice::sweep(
      Vec3(-spacing, 0.0, 0.02), Vec3(columns * spacing, (rows - 1) * spacing, 0.02), rows, speed);
  haptics::LoopOptions options;
  options.rateHz = rate;
  options.workers = workers;
  shapedb::io::QueryOptions query;
  query.fidelity = false;
  auto loop = haptics::HapticLoop::create(objects, device, haptics::databaseAugmenter(*db, query), options);
  if (!loop) {
    std::fprintf(stderr, "haptic_bench: %s\n", loop.error().message.c_str());
    return 1;
  }
  std::printf(
      "haptic_bench: %d fragments (%d rows), %s (%zu entries), %.0f Hz for %.3g s, %d worker(s), "
      "sweep at %.2g m/s\n",
      count, rows, dbPath.c_str(), db->entries().size(), rate, seconds, workers, speed);
  // The platform's share first: the same timing loop, no scene, no worker. Misses here are the machine's
  // (a virtual CPU descheduled by its host, a kernel stall), not the tick's.
  haptics::TrajectoryDevice still = *haptics::TrajectoryDevice::fromKeyframes({{0.0, Vec3::Zero()}});
  auto empty = haptics::HapticLoop::create({}, still, haptics::databaseAugmenter(*db, query), options);
  const haptics::LoopReport base = (*empty)->run(seconds);
  std::printf("  empty loop (baseline): deadline misses %zu, tick start late us p99 %.2f max %.0f\n",
              base.deadlineMisses, base.startLateMicros.p99, base.startLateMicros.max);

  const haptics::LoopReport r = (*loop)->run(seconds);
  std::printf("  ticks %zu, achieved %.2f Hz, realtime priority: %s, loop thread page faults: %zu\n", r.ticks,
              r.achievedRateHz, r.realtimePriority ? "yes" : "no", r.pageFaults);
  std::printf("  tick compute us: p50 %.2f  p99 %.2f  max %.2f   (target p99 <= 100)\n", r.tickMicros.p50,
              r.tickMicros.p99, r.tickMicros.max);
  std::printf("  tick start late us: p50 %.2f  p99 %.2f  max %.0f\n", r.startLateMicros.p50,
              r.startLateMicros.p99, r.startLateMicros.max);
  std::printf("  deadline misses: %zu   (target 0)\n", r.deadlineMisses);
  std::printf(
      "  objects: %zu augmented, %zu failed, %zu pending; augmentation ms p50 %.2f p99 %.2f max %.2f\n",
      r.objectsAugmented, r.objectsFailed, r.objectsPending, r.augmentationMillis.p50,
      r.augmentationMillis.p99, r.augmentationMillis.max);
  std::printf("  contact ticks %zu, largest force %.3g N\n", r.contactTicks, r.maxForce);
  for (const haptics::ObjectOutcome& o : r.objects)
    if (o.state == haptics::ObjectOutcome::State::kFailed) std::printf("  failed: %s\n", o.error.c_str());
  return 0;
}
