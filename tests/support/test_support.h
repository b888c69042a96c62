#pragma once

// Helpers shared by the test suites: seeded random transforms, scratch directories, mesh comparisons.

#include <filesystem>
#include <optional>
#include <random>
#include <string>

#include <shapedb/core/physics.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

#include "synthetic.h"

namespace shapedb::test {

/// A random similarity transform: random rotation, translation in [-range, range]³, uniform scale in
/// [minScale, maxScale] (log-uniform).
core::Mat4 randomSimilarity(std::mt19937_64& rng, double range = 10.0, double minScale = 0.1,
                            double maxScale = 10.0);

/// Largest |a − b| over corresponding vertices, divided by `scale`. Precondition: same vertex count.
double maxVertexDifference(const core::TriangleMesh& a, const core::TriangleMesh& b, double scale = 1.0);

/// A fresh empty directory under the system temp dir, removed when the object dies.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return mPath; }
  std::filesystem::path operator/(const std::string& name) const { return mPath / name; }

 private:
  std::filesystem::path mPath;
};

/// The folder of real meshes ($SHAPEDB_REAL_MESHES, else the build's SHAPEDB_REAL_MESHES), or nothing when
/// it holds no mesh file; `why` then says where it looked.
std::optional<std::filesystem::path> realMeshDirectory(std::string* why = nullptr);

/// In a test body: the real-mesh folder into `var`, or the test skipped with the reason.
#define SHAPEDB_REAL_MESHES_OR_SKIP(var)                                                                 \
  std::string var##Why;                                                                                  \
  const std::optional<std::filesystem::path> var##Found = ::shapedb::test::realMeshDirectory(&var##Why); \
  if (!var##Found) GTEST_SKIP() << var##Why;                                                             \
  const std::filesystem::path var = *var##Found

/// A box [0,nx]×[0,ny]×[0,nz] of unit cubes, each split into six tets around its main diagonal (Kuhn),
/// interior nodes jittered by up to `jitter`: a conforming tet mesh with irregular tets.
core::TetMesh makeTetGrid(int nx, int ny, int nz, double jitter, std::mt19937_64& rng);

/// `outer` with `inner` added as one more shell, scaled by `scale` and moved by `offset` (its vertices and
/// triangles after outer's): wound inward when `cavity` (a void in the solid around it), else as given (a
/// solid of its own).
core::TriangleMesh withShell(core::TriangleMesh outer, const core::TriangleMesh& inner,
                             const core::Vec3& offset, bool cavity, double scale = 1.0);

/// Two unit cubes written as one mesh, the second moved by `offset` (its 8 vertices and 12 triangles
/// after the first's), as an export of two parts is: overlapping, the surface passes through itself;
/// apart, it bounds two solids.
core::TriangleMesh twoUnitBoxes(const core::Vec3& offset);

/// The point a location's barycentric weights give on `mesh`'s nodes.
core::Vec3 interpolate(const core::TetMesh& mesh, const core::TetLocation& location);

/// Writes `content` to `path` byte for byte.
void writeFile(const std::filesystem::path& path, const std::string& content);

/// The whole of `path`, byte for byte ("" if it cannot be read).
std::string readFile(const std::filesystem::path& path);

}  // namespace shapedb::test
