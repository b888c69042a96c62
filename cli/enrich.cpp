// shapedb enrich: objects' exact data computed and learned into a database, in batch.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include <shapedb/io/database.h>
#include <shapedb/io/enrich.h>

#include "commands.h"

namespace shapedb::cli {
namespace {

struct EnrichCommandOptions {
  MeshLoadFlags load;
  std::string database;
  std::vector<std::string> meshes;
  int workers = 0;
  bool json = false;
};

/// One mesh of the batch: its file, and the enricher's answer once it has one.
struct EnrichItem {
  std::string file;
  std::shared_future<Result<io::Learned>> learned;
  bool reported = false;
};

nlohmann::json learnedJson(const std::string& file, const Result<io::Learned>& r) {
  if (!r) return {{"file", file}, {"error", r.error().message}};
  return {{"file", file},
          {"entry_id", r->id},
          {"name", r->name},
          {"computed", r->computed},
          {"seconds", r->seconds},
          {"stage_seconds",
           {{"tetrahedralize", r->stages.tetrahedralize},
            {"modes", r->stages.modes},
            {"total", r->stages.total()}}}};
}

int runEnrich(const EnrichCommandOptions& o) {
  io::Database::OpenOptions open;
  open.learn = true;
  auto db = io::Database::open(o.database, open);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }
  const auto start = std::chrono::steady_clock::now();
  int status = kExitOk;
  std::vector<EnrichItem> items;
  {
    io::EnricherOptions options;
    options.workers =
        o.workers > 0 ? o.workers : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    io::Enricher enricher(*db, options);
    // Loaded one by one as they are submitted: the first computes while the rest are read.
    for (const std::string& file : o.meshes) {
      auto loaded = loadMeshFile(file, o.load);
      if (!loaded) {
        printError(loaded.error().message + flagHint(loaded.error()));
        status = kExitInputError;
        continue;
      }
      items.push_back({file, enricher.submit({std::filesystem::path(file).filename().string(), file,
                                              std::move(loaded->mesh)})});
    }
    // Reported as they finish, so that a long batch shows its progress.
    std::size_t done = 0, computed = 0, known = 0, failed = 0;
    while (done < items.size()) {
      for (EnrichItem& item : items) {
        if (item.reported ||
            item.learned.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
          continue;
        item.reported = true;
        ++done;
        const Result<io::Learned>& r = item.learned.get();
        if (!r) {
          ++failed;
          status = kExitInputError;
          printError(r.error().message + flagHint(r.error()));
          continue;
        }
        ++(r->computed ? computed : known);
        if (o.json) continue;
        const io::EntryRecord* e = db->entry(r->id);
        if (r->computed)
          std::printf("[%zu/%zu] %s: learned as entry %u '%s' in %.1f s (%zu tets)\n", done, items.size(),
                      item.file.c_str(), r->id, r->name.c_str(), r->seconds, e ? e->tets : 0);
        else
          std::printf("[%zu/%zu] %s: already learned, entry %u '%s'\n", done, items.size(), item.file.c_str(),
                      r->id, r->name.c_str());
        std::fflush(stdout);
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.json) {
      nlohmann::json out = {
          {"database", o.database}, {"seconds", seconds}, {"meshes", nlohmann::json::array()}};
      for (const EnrichItem& item : items)
        out["meshes"].push_back(learnedJson(item.file, item.learned.get()));
      std::printf("%s\n", out.dump(2).c_str());
    } else {
      std::printf("%s: %zu learned, %zu already there, %zu failed in %.1f s; %zu entries now\n",
                  o.database.c_str(), computed, known, failed, seconds, db->size());
    }
  }
  return status;
}

}  // namespace

Command addEnrichCommand(CLI::App& parent) {
  auto o = std::make_shared<EnrichCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "enrich",
      "Learn objects into a database: compute each mesh's exact data with the database's own parameters\n"
      "(tet mesh, modes, collision compound, sound data) and add them as a 'learned' entry, so that the\n"
      "mesh, or one like it, matches itself from then on (the scenario database of paper §7, grown from\n"
      "the objects met). Meshes are computed in parallel and committed one by one: an interrupted run\n"
      "keeps what it committed, and running it again computes only the rest (a mesh is known by a hash of\n"
      "its surface as given). Exit status 1 if any mesh failed; the others are learned all the same.");
  app->add_option("DB", o->database, "Database file (shapedb build); must be writable")->required();
  app->add_option("MESH", o->meshes,
                  "Closed surface mesh files (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  addMeshLoadFlags(*app, o->load);
  app->add_option("--workers", o->workers, "Meshes computed at once (0: one per core)")
      ->capture_default_str()
      ->check(CLI::Range(0, 256));
  app->add_flag(
      "--json", o->json,
      "Print one JSON object: {database, seconds, meshes: [{file, entry_id, name, computed, seconds,\n"
      "stage_seconds} or {file, error}]}");
  return {app, [o] { return runEnrich(*o); }};
}

}  // namespace shapedb::cli
