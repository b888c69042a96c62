#include "support/test_support.h"

#include <array>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

#include <Eigen/Geometry>

#include <shapedb/core/primitives.h>

namespace shapedb::test {

core::Mat4 randomSimilarity(std::mt19937_64& rng, double range, double minScale, double maxScale) {
  std::uniform_real_distribution<double> offset(-range, range);
  std::uniform_real_distribution<double> logScale(std::log(minScale), std::log(maxScale));
  core::Mat4 t = core::Mat4::Identity();
  t.topLeftCorner<3, 3>() = std::exp(logScale(rng)) * randomRotation(rng);
  t.topRightCorner<3, 1>() = core::Vec3(offset(rng), offset(rng), offset(rng));
  return t;
}

double maxVertexDifference(const core::TriangleMesh& a, const core::TriangleMesh& b, double scale) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.vertices.size(); ++i)
    worst = std::max(worst, (a.vertices[i] - b.vertices[i]).cwiseAbs().maxCoeff());
  return worst / scale;
}

ScratchDir::ScratchDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  mPath = std::filesystem::temp_directory_path() /
          ("shapedb-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(mPath);
  std::filesystem::create_directories(mPath);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(mPath, ec);
}

void writeFile(const std::filesystem::path& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
}

std::optional<std::filesystem::path> realMeshDirectory(std::string* why) {
  namespace fs = std::filesystem;
  const char* fromEnvironment = std::getenv("SHAPEDB_REAL_MESHES");
  const fs::path folder = fromEnvironment != nullptr && *fromEnvironment != '\0'
                              ? fs::path(fromEnvironment)
                              : fs::path(SHAPEDB_REAL_MESHES_DEFAULT);
  std::error_code ec;
  if (fs::is_directory(folder, ec))
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(folder, ec)) {
      std::string extension = entry.path().extension().string();
      for (char& c : extension)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (extension == ".obj" || extension == ".ply" || extension == ".stl" || extension == ".off")
        return fs::weakly_canonical(folder, ec);
    }
  if (why != nullptr)
    *why = "no real meshes in " + folder.string() +
           " (set SHAPEDB_REAL_MESHES, or the CMake cache variable of that name, to a folder of meshes)";
  return std::nullopt;
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

core::TriangleMesh withShell(core::TriangleMesh outer, const core::TriangleMesh& inner,
                             const core::Vec3& offset, bool cavity, double scale) {
  core::TriangleMesh shell = cavity ? core::flipped(inner) : inner;
  for (core::Vec3& v : shell.vertices)
    v = scale * v + offset;
  core::append(outer, shell);
  return outer;
}

core::TriangleMesh twoUnitBoxes(const core::Vec3& offset) {
  return withShell(core::makeBox({1, 1, 1}), core::makeBox({1, 1, 1}), offset, false);
}

core::TetMesh makeTetGrid(int nx, int ny, int nz, double jitter, std::mt19937_64& rng) {
  core::TetMesh mesh;
  std::uniform_real_distribution<double> u(-jitter, jitter);
  const auto id = [&](int x, int y, int z) {
    return static_cast<std::uint32_t>((z * (ny + 1) + y) * (nx + 1) + x);
  };
  for (int z = 0; z <= nz; ++z)
    for (int y = 0; y <= ny; ++y)
      for (int x = 0; x <= nx; ++x) {
        core::Vec3 p(x, y, z);
        for (int a = 0; a < 3; ++a) {
          const int i = a == 0 ? x : a == 1 ? y : z, n = a == 0 ? nx : a == 1 ? ny : nz;
          if (i > 0 && i < n) p[a] += u(rng);
        }
        mesh.nodes.push_back(p);
      }
  static constexpr int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        for (const auto& path : kPaths) {
          std::array<int, 3> c{x, y, z};
          core::TetMesh::Tet t;
          t[0] = id(c[0], c[1], c[2]);
          for (int k = 0; k < 3; ++k) {
            ++c[path[k]];
            t[k + 1] = id(c[0], c[1], c[2]);
          }
          if (core::tetVolume(core::TetMesh{mesh.nodes, {t}}, 0) < 0) std::swap(t[2], t[3]);
          mesh.tets.push_back(t);
        }
  return mesh;
}

core::Vec3 interpolate(const core::TetMesh& mesh, const core::TetLocation& location) {
  core::Vec3 x = core::Vec3::Zero();
  for (int k = 0; k < 4; ++k)
    x += location.weights[static_cast<std::size_t>(k)] *
         mesh.nodes[mesh.tets[location.tet][static_cast<std::size_t>(k)]];
  return x;
}

}  // namespace shapedb::test
