#include <chrono>

#include <shapedb/volume/correction.h>

namespace shapedb::volume {

Result<CorrectedEntry> correctGeometry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                       const ModalOptions& modal, const CorrectionOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  if (entry.modes.shapes.rows() != static_cast<Eigen::Index>(3 * entry.tetMesh.nodeCount()) ||
      entry.modes.shapes.cols() < 1)
    return Error{ErrorCode::kInvalidArgument, "correction: the entry's mode shapes do not fit its tet mesh"};

  CorrectedEntry out;
  Clock::time_point start = Clock::now();
  auto morphed = morphTetMesh(entry.tetMesh, target, options.morph);
  if (!morphed) return morphed.error();
  out.report.morph = morphed->report;
  out.physics.tetMesh = std::move(morphed->mesh);
  out.physics.massProperties = core::computeTetMassProperties(out.physics.tetMesh);
  out.report.morphSeconds = seconds(start);

  // The entry's modes on the same nodes are the seeds: the morph moved the nodes, not their numbering.
  start = Clock::now();
  ModalOptions unit = modal;
  unit.material = {.youngsModulus = 1.0, .poissonRatio = modal.material.poissonRatio, .density = 1.0};
  auto modes = computeModesFrom(out.physics.tetMesh, entry.modes.shapes, unit, &out.report.solves);
  if (!modes) return withContext(modes.error(), "correction: modes on the morphed tets");
  out.physics.modes = std::move(modes).value();
  out.report.modesSeconds = seconds(start);

  out.physics.collision = entry.collision;
  out.physics.sound.frequenciesHz = out.physics.modes.frequenciesHz();
  out.physics.sound.damping = entry.sound.damping;
  return out;
}

}  // namespace shapedb::volume
