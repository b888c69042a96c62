// The learning database in a haptic scene: every mesh of a folder appears twice in a row of objects, the
// proxy sweeps the row, and each object it comes near is augmented from the database and, with learning
// on, learned in the background and swapped to its exact data once they are there.
//
//   build/release/bin/learning_bench DB MESH_FOLDER TRUTH_CSV... [--seconds S]   (default 120)
//
// DB is copied (the original is left as it was). TRUTH_CSV are `shapedb bench` results (evaluation.csv)
// holding the meshes' direct computations (f1_truth_hz per shape, steel): the errors below are against
// them. Reports, per mesh and as medians and p90:
//   - the first appearance's first-frequency error: the database's answer before it learned the mesh
//     (a query on the untouched copy, as the loop's augmentation makes it);
//   - the second appearance's: the answer once learning ran (a query after the loop);
//   - the time to exact data: entering the radius → the learned data in use in the loop;
//   - the loop's deadline misses with learning running, beside those of the same loop without learning
//     and of an empty loop (the platform's own); for each loop, how late its ticks started, the loop
//     thread's page faults, and the hypervisor's steal time meanwhile (on a virtual machine a vCPU the
//     host takes away for milliseconds makes ticks late with no cause in this process).
// Meshes are read in metres, as `shapedb bench` read them for its truth.

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include <shapedb/core/statistics.h>
#include <shapedb/haptics/scene.h>
#include <shapedb/io/enrich.h>
#include <shapedb/io/mesh_io.h>

namespace {

using shapedb::core::Vec3;
namespace haptics = shapedb::haptics;
namespace io = shapedb::io;
namespace fs = std::filesystem;

std::vector<std::string> splitLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted)
      fields.emplace_back();
    else
      fields.back() += c;
  }
  return fields;
}

/// Shape name → first non-rigid frequency computed directly, from `shapedb bench` CSVs.
std::map<std::string, double> readTruth(const std::vector<std::string>& files) {
  std::map<std::string, double> truth;
  for (const std::string& file : files) {
    std::ifstream in(file);
    std::string line;
    if (!std::getline(in, line)) continue;
    const std::vector<std::string> header = splitLine(line);
    std::size_t shape = 0, f1 = 0;
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == "shape") shape = i;
      if (header[i] == "f1_truth_hz") f1 = i;
    }
    while (std::getline(in, line)) {
      const std::vector<std::string> row = splitLine(line);
      if (row.size() == header.size() && !row[f1].empty()) truth[row[shape]] = std::stod(row[f1]);
    }
  }
  return truth;
}

double firstFrequency(const io::Database& db, const shapedb::core::TriangleMesh& mesh) {
  io::QueryOptions q;
  q.fidelity = false;
  auto r = db.query(mesh, q);
  if (!r || !r->physics || r->physics->frequenciesHz().size() == 0) return std::nan("");
  return r->physics->frequenciesHz()[0];
}

std::string percent(double x) {
  char b[32];
  std::snprintf(b, sizeof b, std::isfinite(x) ? "%+.1f %%" : "n/a", 100.0 * x);
  return b;
}

/// The time the hypervisor ran something else while this machine's CPUs had work (steal, all CPUs summed,
/// from /proc/stat), in seconds since boot; NaN where the system does not say. A tick that starts late with
/// no page fault while steal grows was lost to the host, not to this process.
double stealSeconds() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  double field = 0.0, steal = 0.0;
  if (!(in >> cpu) || cpu != "cpu") return std::nan("");
  for (int i = 0; i < 8; ++i) {  // user nice system idle iowait irq softirq steal
    if (!(in >> field)) return std::nan("");
    steal = field;
  }
  return steal / static_cast<double>(sysconf(_SC_CLK_TCK));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> positional;
  double seconds = 120.0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc)
      seconds = std::atof(argv[++i]);
    else if (argv[i][0] == '-') {
      std::fprintf(stderr, "learning_bench: unknown option %s\n", argv[i]);
      return 2;
    } else
      positional.push_back(argv[i]);
  }
  if (positional.size() < 3 || seconds <= 0.0) {
    std::fprintf(stderr, "usage: learning_bench DB MESH_FOLDER TRUTH_CSV... [--seconds S]\n");
    return 2;
  }
  const fs::path work = fs::temp_directory_path() / "shapedb-learning-bench.db";
  fs::remove(work);
  fs::copy_file(positional[0], work);
  const std::map<std::string, double> truth =
      readTruth(std::vector<std::string>(positional.begin() + 2, positional.end()));

  // The meshes with a truth, each twice in a row along x (below): the proxy meets
  // every first appearance before any second.
  auto files = io::listMeshFiles(positional[1]);
  if (!files) {
    std::fprintf(stderr, "learning_bench: %s\n", files.error().message.c_str());
    return 1;
  }
  std::vector<std::pair<std::string, shapedb::core::TriangleMesh>> meshes;
  for (const fs::path& file : *files) {
    if (!truth.count(file.stem().string())) continue;
    auto loaded = io::loadMesh(file);
    if (!loaded) continue;
    meshes.emplace_back(file.stem().string(), std::move(loaded->mesh));
  }
  if (meshes.empty()) {
    std::fprintf(stderr, "learning_bench: no mesh of %s has a truth in the CSVs\n", positional[1].c_str());
    return 1;
  }
  // In the scene every mesh is scaled to 10 cm across (the learned entries are scale-free: the queries
  // below, on the meshes as read, find them all the same), 15 cm apart, and the proxy crosses the row once
  // in the run: every first appearance in its first half, every second in its second.
  const double spacing = 0.15;
  std::vector<haptics::SceneObject> objects;
  for (int copy = 0; copy < 2; ++copy)
    for (const auto& [name, mesh] : meshes) {
      haptics::SceneObject o{name + (copy == 0 ? "" : " (again)"), mesh};
      const shapedb::core::Bounds b = shapedb::core::computeBounds(o.mesh);
      const double scale = 0.1 / (b.max - b.min).norm();
      const Vec3 at(spacing * static_cast<double>(objects.size()), 0.0, 0.0);
      for (Vec3& v : o.mesh.vertices)
        v = at + scale * (v - 0.5 * (b.min + b.max));
      objects.push_back(std::move(o));
    }
  const double length = spacing * static_cast<double>(objects.size());
  const double sweepSeconds = seconds;
  auto device = [&] {
    return *haptics::TrajectoryDevice::fromKeyframes(
        {{0.0, Vec3(-spacing, 0.0, 0.0)}, {sweepSeconds, Vec3(length, 0.0, 0.0)}});
  };
  haptics::LoopOptions options;
  options.augmentationRadius = 0.03;
  io::QueryOptions query;
  query.fidelity = false;

  // 1. First appearances: the untouched database's answers.
  io::Database::OpenOptions learn;
  learn.learn = true;
  auto db = io::Database::open(work, learn);
  if (!db) {
    std::fprintf(stderr, "learning_bench: %s\n", db.error().message.c_str());
    return 1;
  }
  std::vector<double> first;
  for (const auto& [name, mesh] : meshes)
    first.push_back(firstFrequency(*db, mesh) / truth.at(name) - 1.0);

  // 2. The platform's misses, then the loop's without learning, then with.
  std::printf("learning_bench: %zu meshes, each twice; %s (%zu entries); %.0f s at 1 kHz, sweep %.3g m/s\n",
              meshes.size(), positional[0].c_str(), db->size(), sweepSeconds, length / sweepSeconds);
  haptics::TrajectoryDevice still = *haptics::TrajectoryDevice::fromKeyframes({{0.0, Vec3::Zero()}});
  const auto empty = haptics::HapticLoop::create({}, still, haptics::databaseAugmenter(*db, query), options);
  std::array<double, 3> steal{};  // the hypervisor's during each loop, seconds
  const auto runLoop = [&](haptics::HapticLoop& loop, std::size_t i) {
    const double before = stealSeconds();
    haptics::LoopReport report = loop.run(sweepSeconds);
    steal[i] = stealSeconds() - before;
    return report;
  };
  const haptics::LoopReport base = runLoop(**empty, 0);
  haptics::TrajectoryDevice plainDevice = device();
  const auto plain =
      haptics::HapticLoop::create(objects, plainDevice, haptics::databaseAugmenter(*db, query), options);
  const haptics::LoopReport without = runLoop(**plain, 1);
  haptics::LoopReport with;
  {
    io::Enricher enricher(*db);
    haptics::TrajectoryDevice learningDevice = device();
    const auto learning = haptics::HapticLoop::create(
        objects, learningDevice, haptics::learningAugmenter(*db, enricher, query), options);
    with = runLoop(**learning, 2);
    enricher.wait();  // the rest, for the second appearances below
  }

  // 3. Second appearances: the database's answers once it learned.
  std::printf(
      "\n| mesh | truth f1 | first appearance | second appearance | time to exact data | second copy's first "
      "data |\n");
  std::printf("|---|---:|---:|---:|---:|---|\n");
  std::vector<double> second, exactSeconds;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const auto& [name, mesh] = meshes[i];
    second.push_back(firstFrequency(*db, mesh) / truth.at(name) - 1.0);
    const haptics::ObjectOutcome& a = with.objects[i];
    const haptics::ObjectOutcome& b = with.objects[i + meshes.size()];
    char exact[32] = "not in the run";
    if (a.upgraded) {
      std::snprintf(exact, sizeof exact, "%.1f s", a.upgradeSeconds);
      exactSeconds.push_back(a.upgradeSeconds);
    } else if (!a.upgradeError.empty()) {
      std::snprintf(exact, sizeof exact, "failed (below)");
    }
    std::printf("| %s | %.1f Hz | %s | %s | %s | %s |\n", name.c_str(), truth.at(name),
                percent(first[i]).c_str(), percent(second[i]).c_str(), exact,
                b.state == haptics::ObjectOutcome::State::kReady
                    ? (b.upgraded ? (b.firstSource + ", then learned").c_str() : b.source.c_str())
                    : "not reached");
  }
  // Why an object's exact data did not come: its augmentation or its upgrade failed.
  for (const haptics::ObjectOutcome& o : with.objects) {
    if (o.state == haptics::ObjectOutcome::State::kFailed)
      std::printf("%s: not augmented: %s\n", o.name.c_str(), o.error.c_str());
    if (!o.upgradeError.empty())
      std::printf("%s: upgrade failed: %s\n", o.name.c_str(), o.upgradeError.c_str());
  }
  const auto absolute = [](std::vector<double> v) {
    for (double& x : v)
      x = std::abs(x);
    return v;
  };
  std::printf("\n| | median abs. error | p90 |\n|---|---:|---:|\n");
  std::printf("| first appearance | %.1f %% | %.1f %% |\n", 100.0 * shapedb::core::median(absolute(first)),
              100.0 * shapedb::core::percentile(absolute(first), 0.9));
  std::printf("| second appearance | %.2f %% | %.2f %% |\n", 100.0 * shapedb::core::median(absolute(second)),
              100.0 * shapedb::core::percentile(absolute(second), 0.9));
  std::printf(
      "\ntime to exact data in the loop: median %.1f s, max %.1f s (%zu of %zu swapped in during the run)\n",
      shapedb::core::median(exactSeconds),
      exactSeconds.empty() ? 0.0 : shapedb::core::percentile(exactSeconds, 1.0), exactSeconds.size(),
      meshes.size());
  std::printf(
      "deadline misses in %.0f s: empty loop %zu, without learning %zu, with learning %zu "
      "(tick us p99 %.2f, max %.1f)\n",
      sweepSeconds, base.deadlineMisses, without.deadlineMisses, with.deadlineMisses, with.tickMicros.p99,
      with.tickMicros.max);
  // Why a tick misses: it ran long, it started late (the loop thread waited for a core, or for the memory
  // map in a page fault), or both.
  const std::array<std::pair<const char*, const haptics::LoopReport*>, 3> loops = {
      {{"empty loop", &base}, {"without learning", &without}, {"with learning", &with}}};
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const auto& [name, r] = loops[i];
    std::printf(
        "  %s: tick start late us p50 %.1f, p99 %.1f, max %.0f; loop thread page faults %zu; "
        "real-time priority %s; hypervisor steal %s\n",
        name, r->startLateMicros.p50, r->startLateMicros.p99, r->startLateMicros.max, r->pageFaults,
        r->realtimePriority ? "yes" : "no",
        std::isfinite(steal[i]) ? (std::to_string(std::lround(1e3 * steal[i])) + " ms").c_str() : "unknown");
  }
  fs::remove(work);
  return 0;
}
