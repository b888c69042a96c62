#include <chrono>
#include <cmath>

#include <shapedb/volume/describe.h>
#include <shapedb/volume/entry.h>

namespace shapedb::volume {
namespace {

class Stopwatch {
 public:
  /// Seconds since the last call (or construction).
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - mLast).count();
    mLast = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point mLast = std::chrono::steady_clock::now();
};

}  // namespace

TetrahedralizeOptions entryMeshing(ElementOrder order) {
  TetrahedralizeOptions options;
  if (order == ElementOrder::kQuadratic) {
    options.maxRadiusEdgeRatio = 3.0;
    options.maxVolumeFraction = 1.0 / 100.0;
  } else {
    options.maxRadiusEdgeRatio = 1.5;
    options.maxVolumeFraction = 1.0 / 600.0;
  }
  return options;
}

EntryOptions withElements(EntryOptions options, ElementOrder order) {
  options.modal.order = order;
  const TetrahedralizeOptions bounds = entryMeshing(order);
  options.tetgen.maxRadiusEdgeRatio = bounds.maxRadiusEdgeRatio;
  options.tetgen.maxVolumeFraction = bounds.maxVolumeFraction;
  return options;
}

Result<EntryData> computeEntry(const core::TriangleMesh& surface, const EntryOptions& options) {
  EntryData entry;
  Stopwatch clock;
  if (Status valid = core::validateMesh(surface); !valid) return valid.error();
  auto mass = core::computeMassProperties(surface);
  if (!mass) return mass.error();
  entry.surfaceMassProperties = *mass;
  auto normalization = core::normalize(surface, *mass);
  if (!normalization) return withContext(normalization.error(), "normalize");
  entry.normalization = *normalization;
  const core::TriangleMesh canonical = core::transformed(surface, normalization->canonicalFromMesh);
  entry.times.normalize = clock.lap();

  // TetGen gets the surface as it came, then its nodes go to the canonical frame (a similarity with
  // positive determinant: tets stay positive). The canonical frame's rotated coordinates put the corners
  // of a box's faces off their plane by round-off, and TetGen 1.5 aborts on some such boxes (box-00221
  // of the default catalog did).
  auto tets = tetrahedralize(surface, options.tetgen);
  if (!tets) return withContext(tets.error(), "tetrahedralize");
  entry.physics.tetMesh = std::move(tets).value();
  for (core::Vec3& p : entry.physics.tetMesh.nodes)
    p = core::transformPoint(normalization->canonicalFromMesh, p);
  // What the database stores must pass its reader's checks in this frame (fragment-00502 had a tet
  // flattened by the move): the nearly flat ones go, and the fill check below still holds the rest.
  dropFlatTets(entry.physics.tetMesh);
  if (core::faceConnectedPieces(entry.physics.tetMesh) > 1) {
    // Dropping them left tets held by an edge or a node alone (a mechanism: a plate fragment rang at
    // 18 Hz instead of 11 kHz). The canonical surface meshed as it is has nothing to flatten.
    auto direct = tetrahedralize(canonical, options.tetgen);
    if (!direct) return withContext(direct.error(), "tetrahedralize (in the canonical frame)");
    entry.physics.tetMesh = std::move(direct).value();
  }
  if (Status valid = core::validateTetMesh(entry.physics.tetMesh); !valid)
    return Error{ErrorCode::kParse, "tetrahedralize: in the canonical frame, " + valid.error().message};
  entry.physics.massProperties = core::computeTetMassProperties(entry.physics.tetMesh);
  // The tets must fill the surface: unit volume, centre at the origin, in the canonical frame.
  const core::MassProperties& m = entry.physics.massProperties;
  if (std::abs(m.volume - 1.0) > 1e-9 || m.centerOfMass.norm() > 1e-9)
    return Error{ErrorCode::kParse, "tetrahedralize: the tet mesh does not fill the surface (volume " +
                                        std::to_string(m.volume) + " of 1)"};
  entry.times.tetrahedralize = clock.lap();

  Describer describer(options.descriptor);
  for (core::DescriptorKind kind :
       {core::DescriptorKind::kMoment, core::DescriptorKind::kVoxel, core::DescriptorKind::kCentroidVoxel}) {
    core::DescriptorOptions o = options.descriptor;
    o.kind = kind;
    auto d = kind == options.descriptor.kind ? describer.describe(surface, *normalization)
                                             : volume::describe(surface, *normalization, o);
    if (!d) return withContext(d.error(), "describe");
    entry.descriptors[static_cast<std::size_t>(kind)] = std::move(d).value();
  }
  entry.times.describe = clock.lap();

  ModalOptions modal = options.modal;
  modal.material = core::unitMaterial(options.modal.material.poissonRatio);
  auto modes = computeModes(entry.physics.tetMesh, modal);
  if (!modes) return withContext(modes.error(), "modes");
  entry.physics.modes = std::move(modes).value();
  entry.times.modes = clock.lap();

  auto collision = fitCollisionCompound(canonical, options.collision);
  if (!collision) return withContext(collision.error(), "collision");
  entry.physics.collision = std::move(collision).value();
  entry.times.collision = clock.lap();

  entry.physics.sound.frequenciesHz = entry.physics.modes.frequenciesHz();
  entry.physics.sound.damping = options.damping;
  return entry;
}

}  // namespace shapedb::volume
