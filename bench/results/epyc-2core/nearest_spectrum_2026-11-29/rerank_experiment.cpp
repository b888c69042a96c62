// Scratch experiment (not for commit): the nearest tier answered by the best of k candidates by a
// fidelity term. Prints per mesh and candidate: rank, entry, f1, mean deviation, max moment error,
// predicted error, descriptor distance.
#include <cmath>
#include <cstdio>
#include <string>

#include <shapedb/core/adapt.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>

using namespace shapedb;

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  auto db = io::Database::open(argv[1]);
  if (!db) {
    std::fprintf(stderr, "%s\n", db.error().message.c_str());
    return 1;
  }
  std::printf("shape,rank,entry,f1,mean_dev,max_dev,max_moment,predicted,distance\n");
  for (int i = 3; i < argc; ++i) {
    auto mesh = io::loadMesh(argv[i]);
    if (!mesh) {
      std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
      continue;
    }
    io::QueryOptions options;
    options.fidelity = true;
    options.search.k = std::atoi(argv[2]);
    auto r = db->query(mesh->mesh, options);
    if (!r || !r->physics) {
      std::fprintf(stderr, "%s: query failed\n", argv[i]);
      continue;
    }
    std::string name = argv[i];
    name = name.substr(name.find_last_of('/') + 1);
    name = name.substr(0, name.find_last_of('.'));
    for (std::size_t k = 0; k < r->matches.size(); ++k) {
      const io::MatchReport& m = r->matches[k];
      auto data = db->physics(m.match.entry);
      if (!data) continue;
      auto a = core::adapt(**data, r->normalization, r->massProperties, m.match.orientation, options.material,
                           db->parameters().entry.damping);
      if (!a) continue;
      std::printf("%s,%zu,%s,%.6g,%.5g,%.5g,%.5g,%.5g,%.5g\n", name.c_str(), k, m.entry->name.c_str(),
                  std::sqrt(a->eigenvalues[0]) / (2 * M_PI), m.fidelity->meanDeviation,
                  m.fidelity->maxDeviation, m.fidelity->maxMomentError,
                  m.predictedFrequencyError.value_or(-1), m.fidelity->descriptorDistance);
    }
    std::fflush(stdout);
  }
}
