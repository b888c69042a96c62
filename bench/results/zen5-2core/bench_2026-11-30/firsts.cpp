// What a mesh's first corrected query pays for its entries' plans (volume::ModalPlan, volume::MorphPlan,
// kept in the entry cache): each round opens the database afresh (an empty cache), queries each mesh once
// uncorrected (which fetches its entries, as shapedb bench's earlier methods do) and then twice corrected
// (the default three candidates, the fidelity report off), and times the two corrected queries. Prints
// each mesh's median first and second corrected query over the rounds. A measurement program, not built
// with the project: from build/release,
//   g++ -std=c++20 -O2 -march=native -ffp-contract=off -I../../core/include -I../../io/include \
//     -I../../volume/include -I/usr/include/eigen3 firsts.cpp -o firsts (the libraries as for
//     ../block_solves_2026-11-30/warm_queries.cpp)
//   ./firsts DB MESH... ROUNDS
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>

using namespace shapedb;

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int main(int argc, char** argv) {
  if (argc < 4) return 2;
  const int rounds = std::atoi(argv[argc - 1]);
  std::vector<core::TriangleMesh> meshes;
  for (int a = 2; a < argc - 1; ++a) {
    auto loaded = io::loadMesh(argv[a]);
    if (!loaded) {
      std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
      return 1;
    }
    meshes.push_back(loaded->mesh);
  }
  std::vector<std::vector<double>> first(meshes.size()), second(meshes.size());
  for (int r = 0; r < rounds; ++r) {
    auto db = io::Database::open(argv[1]);
    if (!db) return 1;
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      io::QueryOptions q;
      q.fidelity = false;
      static_cast<void>(db->query(meshes[i], q));
      q.correct = true;
      for (auto* times : {&first[i], &second[i]}) {
        const auto start = std::chrono::steady_clock::now();
        static_cast<void>(db->query(meshes[i], q));
        times->push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      }
    }
  }
  for (std::size_t i = 0; i < meshes.size(); ++i)
    std::printf("%-40s first %.1f ms  second %.1f ms\n", argv[i + 2], median(first[i]), median(second[i]));
}
