#include "support/test_support.h"

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

core::Mat3 randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

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

}  // namespace shapedb::test
