#include <chrono>
#include <cmath>

#include <shapedb/core/mass_properties.h>
#include <shapedb/volume/correction.h>

namespace shapedb::volume {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

Result<MorphedEntry> morphEntry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                const CorrectionOptions& options) {
  if (entry.modes.shapes.rows() != static_cast<Eigen::Index>(3 * entry.tetMesh.nodeCount()) ||
      entry.modes.shapes.cols() < 1)
    return Error{ErrorCode::kInvalidArgument, "correction: the entry's mode shapes do not fit its tet mesh"};
  const Clock::time_point start = Clock::now();
  auto morphed = morphTetMesh(entry.tetMesh, target, options.morph);
  if (!morphed) return morphed.error();
  MorphedEntry out;
  out.report.morph = morphed->report;
  out.tetMesh = std::move(morphed->mesh);
  // The morphed tets fill the target only as far as the projection went (a boundary node held back off a
  // sharp edge cuts the corner): scaled about their centre of mass to the target's volume, so that their
  // modes are those of a body of the query's size and mass, as an entry's are.
  if (Result<core::MassProperties> targetMass = core::computeMassProperties(target); targetMass) {
    const core::MassProperties own = core::computeTetMassProperties(out.tetMesh);
    const double scale = std::cbrt(targetMass->volume / own.volume);
    if (std::isfinite(scale) && scale > 0.0) {
      out.report.volumeScale = scale;
      for (core::Vec3& p : out.tetMesh.nodes)
        p = own.centerOfMass + scale * (p - own.centerOfMass);
    }
  }
  out.report.morphSeconds = secondsSince(start);
  return out;
}

Result<CorrectedEntry> correctMorphed(const core::PhysicalData& entry, MorphedEntry morphed,
                                      const ModalOptions& modal) {
  CorrectedEntry out;
  out.report = morphed.report;
  out.physics.tetMesh = std::move(morphed.tetMesh);
  out.physics.massProperties = core::computeTetMassProperties(out.physics.tetMesh);

  // The entry's modes on the same nodes are the seeds: the morph moved the nodes, not their numbering.
  const Clock::time_point start = Clock::now();
  ModalOptions unit = modal;
  unit.material = core::unitMaterial(modal.material.poissonRatio);
  auto modes = computeModesFrom(out.physics.tetMesh, entry.modes.shapes, unit, &out.report.solves);
  if (!modes) return withContext(modes.error(), "correction: modes on the morphed tets");
  out.physics.modes = std::move(modes).value();
  out.report.modesSeconds = secondsSince(start);

  out.physics.collision = entry.collision;
  out.physics.sound.frequenciesHz = out.physics.modes.frequenciesHz();
  out.physics.sound.damping = entry.sound.damping;
  return out;
}

Result<CorrectedEntry> correctGeometry(const core::PhysicalData& entry, const core::TriangleMesh& target,
                                       const ModalOptions& modal, const CorrectionOptions& options) {
  auto morphed = morphEntry(entry, target, options);
  if (!morphed) return morphed.error();
  return correctMorphed(entry, std::move(morphed).value(), modal);
}

}  // namespace shapedb::volume
