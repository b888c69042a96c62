#pragma once
// The `shapedb drop` scenario as one call: surface meshes given their mass properties and collision
// compounds by a database query, raised together above a floor, dropped with simulateDrop
// (rigid_drop.h), and summarized; optionally rendered, frame by frame, with a fixed framing.
// Built with haptics_rigid, only when Bullet is found (SHAPEDB_HAVE_BULLET).

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <shapedb/core/material.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/haptics/rigid_drop.h>
#include <shapedb/io/database.h>

namespace shapedb::haptics {

/// The meshes to drop, world frame (z up, metres), each with a name for reports.
struct DropScene {
  std::vector<core::TriangleMesh> meshes;
  std::vector<std::string> names;  ///< one per mesh
};

struct DropSceneOptions {
  core::Material material;  ///< every body's material (the query adapts the entry's data to it)
  double height = 0.3;      ///< the lowest collision point of all bodies starts this high (m)
  /// seconds, time step, friction, restitution, recordEvery; its lift is set from `height`.
  DropOptions drop;
};

/// A mesh that got no physical data, and why (its query's error).
struct SkippedMesh {
  std::string name;
  Error error;
};

/// What was dropped and what became of it.
struct DropSceneReport {
  std::vector<RigidBody> bodies;              ///< one per mesh that got physical data
  std::vector<std::size_t> source;            ///< the mesh index of each body
  std::vector<SkippedMesh> skipped;           ///< each mesh without physical data
  DropOptions options;                        ///< as simulated
  DropReport report;                          ///< per body in the order of `bodies`
  double totalMass = 0.0;                     ///< kg
  double deepest = 0.0;                       ///< the lowest z any body reached (≤ 0: into the floor)
  double deepestAtEnd = 0.0;                  ///< the same at the end
  double lastRest = 0.0;                      ///< the latest rest time of any body (s)
  double energyStart = 0.0, energyEnd = 0.0;  ///< kinetic + potential (J)
};

/// Queries `database` for every mesh of `scene` (no linking, no fidelity), raises all bodies together
/// so that their lowest collision point is at options.height, and drops them. A mesh whose query
/// fails or has no physical data is skipped and listed. Errors: kInvalidArgument when the scene's names
/// and meshes differ in number; when no mesh gets physical data, the first mesh's error, its message
/// listing why mesh by mesh; simulateDrop's errors.
Result<DropSceneReport> dropOnFloor(const io::Database& database, const DropScene& scene,
                                    const DropSceneOptions& options);

/// Writes frame-0000.png, frame-0001.png, ... into `directory` (created if missing), one per pose
/// recorded (options.drop.recordEvery > 0): the bodies' surfaces on a floor under the start's footprint
/// with a backdrop as high as the start, seen from the front and a little above. Errors: kIo naming
/// the directory or file.
Status saveDropFrames(const DropScene& scene, const DropSceneReport& dropped, double height,
                      const std::filesystem::path& directory);

}  // namespace shapedb::haptics
