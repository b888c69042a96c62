// Each mesh of DIR queried twice with the geometry correction (centroid-voxel, three candidates), one
// Database for all: prints the first five corrected frequencies of each query to 17 digits, for comparing
// two builds' answers bit for bit (diff). Built as coldwarm.cpp; ./frequencies DB DIR.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
using namespace shapedb;
int main(int argc, char** argv) {
  auto db = io::Database::open(argv[1]);
  std::vector<std::filesystem::path> files;
  for (auto& e : std::filesystem::directory_iterator(argv[2]))
    files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (auto& f : files) {
    auto m = io::loadMesh(f);
    if (!m) continue;
    for (int pass = 0; pass < 2; ++pass) {
      io::QueryOptions q;
      q.descriptor = core::DescriptorKind::kCentroidVoxel;
      q.search.k = 1;
      q.correct = true;
      q.correctionCandidates = 3;
      auto r = db->query(m->mesh, q);
      if (!r || !r->physics) {
        std::printf("%s fail\n", f.filename().c_str());
        continue;
      }
      const Eigen::VectorXd hz = r->physics->frequenciesHz();
      std::printf("%s %d", f.filename().c_str(), pass);
      for (int i = 0; i < 5 && i < static_cast<int>(hz.size()); ++i)
        std::printf(" %.17g", hz[i]);
      std::printf("\n");
    }
  }
}
