#pragma once

// Checks shared by the mesh file tests: a file that must load, one that must fail with a message that
// names it, and the volume of what was read.

#include <filesystem>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/io/mesh_io.h>

namespace shapedb::io::test_checks {

inline LoadedMesh mustLoad(const std::filesystem::path& path, const LoadOptions& options = {}) {
  Result<LoadedMesh> loaded = loadMesh(path, options);
  EXPECT_TRUE(loaded.ok()) << loaded.error().message;
  return loaded.ok() ? *loaded : LoadedMesh{};
}

inline Error mustFail(const std::filesystem::path& path, const LoadOptions& options = {}) {
  Result<LoadedMesh> loaded = loadMesh(path, options);
  EXPECT_FALSE(loaded.ok()) << path << " loaded but should not have";
  if (loaded.ok()) return Error{ErrorCode::kIo, ""};
  // Every message names the file.
  EXPECT_EQ(loaded.error().message.rfind(path.string() + ": ", 0), 0u) << loaded.error().message;
  return loaded.error();
}

inline double volumeOf(const core::TriangleMesh& mesh) {
  Result<core::MassProperties> mp = core::computeMassProperties(mesh);
  EXPECT_TRUE(mp.ok()) << mp.error().message;
  return mp.ok() ? mp->volume : 0.0;
}

}  // namespace shapedb::io::test_checks
