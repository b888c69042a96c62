// Fuzz target: one mesh file format (kShapedbFuzzFormat: "obj", "ply", "off", "stl", "gltf" or "glb", defined
// by each target in a source that tests/fuzz/CMakeLists.txt generates), read as users' files are
// (io::loadMesh), then, when it loads as a closed surface, the front half of a query: exact mass properties
// and the canonical frame. Properties checked beyond "no crash, no leak, no UB": every error names the file;
// a mesh that loads is valid (indices in range, coordinates finite); a frame that is returned is finite.

#include <cmath>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/io/mesh_io.h>

#include "fuzz_support.h"

/// The format this target reads, as a file extension without its dot.
extern const char kShapedbFuzzFormat[];

namespace shapedb::fuzz {
namespace {

void checkLoaded(const io::LoadedMesh& loaded) {
  SHAPEDB_FUZZ_CHECK(!loaded.mesh.triangles.empty());
  SHAPEDB_FUZZ_CHECK(core::validateMesh(loaded.mesh, {.allowDegenerateFaces = true}).ok());
  if (!loaded.topology.isClosed() || !loaded.topology.isConsistentlyOriented()) return;
  Result<core::MassProperties> mass = core::computeMassProperties(loaded.mesh, loaded.topology);
  if (!mass) return;
  SHAPEDB_FUZZ_CHECK(std::isfinite(mass->volume) && mass->volume > 0.0);
  Result<core::Normalization> frame = core::normalize(loaded.mesh, *mass);
  if (!frame) return;
  SHAPEDB_FUZZ_CHECK(std::isfinite(frame->scale) && frame->scale > 0.0);
  SHAPEDB_FUZZ_CHECK(frame->canonicalFromMesh.allFinite() && frame->canonicalMoments.allFinite());
}

void loadBothWays(const std::filesystem::path& path) {
  for (const bool allowDegenerate : {false, true}) {
    Result<io::LoadedMesh> loaded = io::loadMesh(path, {.allowDegenerateFaces = allowDegenerate});
    if (loaded) {
      checkLoaded(*loaded);
      return;
    }
    SHAPEDB_FUZZ_CHECK(loaded.error().message.rfind(path.string() + ": ", 0) == 0);
    if (loaded.error().code != ErrorCode::kDegenerateFace) return;
  }
}

}  // namespace
}  // namespace shapedb::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path = shapedb::fuzz::scratchPath(std::string(".") + kShapedbFuzzFormat);
  shapedb::fuzz::writeInput(path, data, size);
  shapedb::fuzz::loadBothWays(path);
  return 0;
}
