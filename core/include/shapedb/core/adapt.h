#pragma once
// Adaptation (paper §5; docs/architecture.md, "Adaptation and the stretch correction"): a database
// entry's physical data, stored in its canonical frame for unit volume, density and Young's modulus, carried
// to the query's frame, size and material. And linking (paper eq. 7): the query's surface vertices embedded
// in the adapted tets.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/material.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/stretch.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// Where an entry's canonical frame lands in the query's frame: p = translation + scale · rotation · e.
/// For a query normalized by T (p' = s Rᵀ (p − c)) and matched in orientation O (the entry's canonical
/// frame is O times the query's): rotation = R Oᵀ, translation = c, scale = L = 1/s = V^(1/3).
struct Placement {
  Mat3 rotation = Mat3::Identity();
  Vec3 translation = Vec3::Zero();
  double scale = 1.0;
  Vec3 toQuery(const Vec3& e) const { return translation + scale * (rotation * e); }
  Vec3 toEntry(const Vec3& p) const { return rotation.transpose() * (p - translation) / scale; }
};
Placement placementOf(const Normalization& query, const Mat3& orientation);

/// An entry's physical data in the query's frame, size and material.
struct AdaptedPhysics {
  Material material;
  Placement placement;
  TetMesh tetMesh;                ///< nodes in the query's frame, metres
  MassProperties massProperties;  ///< the query's own (exact, from its surface) at the material's density
  /// The entry's tets as placed: what the retrieved data assume. Compare with massProperties.
  MassProperties entryMassProperties;
  Eigen::VectorXd eigenvalues;  ///< ω², (rad/s)², ascending: ω = sqrt(E/ρ) ω' / L
  /// The factors by which the entry was stretched along its canonical axes to take the query's second
  /// moments before its modes were adapted (stretch correction; (1, 1, 1) without it). The tet mesh and
  /// the collision compound are not stretched.
  Vec3 stretch = Vec3::Ones();
  /// 3·nodes × modes, in the query's frame, M-orthonormal for the mass matrix of tetMesh at the
  /// material's density: φ = R φ' / sqrt(ρ L³), φ' the entry's modes (stretched ones with the correction).
  Eigen::MatrixXd modeShapes;
  CollisionCompound collision;  ///< shapes in the query's frame; coverage and overshoot are the entry's
  RayleighDamping damping;      ///< the database's, applied to the adapted frequencies
  std::vector<std::string> warnings;

  Eigen::VectorXd frequenciesHz() const;  ///< ω / 2π
  Eigen::VectorXd dampingRatios() const;  ///< ζ per mode
};

/// Adapts `entry` to a query with normalization `query` (its exact mass properties at unit density in
/// `queryMass`) matched in orientation `orientation` (Match::orientation). A material whose Poisson
/// ratio differs from the database's by more than 0.01 adds a warning: the mode shapes and the ratios
/// of the frequencies are those of the database's ratio. With `stretch` (computeStretchBasis of the
/// entry), the modes are those of the entry stretched along its canonical axes until its second moments
/// equal the query's (stretch.h); a stretch the correction cannot take leaves the modes uncorrected and
/// adds a warning. Errors: validateMaterial's; kInvalidArgument for an entry whose modes do not fit its
/// tet mesh.
Result<AdaptedPhysics> adapt(const PhysicalData& entry, const Normalization& query,
                             const MassProperties& queryMass, const Mat3& orientation,
                             const Material& material, const RayleighDamping& damping,
                             const StretchBasis* stretch = nullptr);

/// One of a query's nearest entries, for blendSpectra: its eigenvalues (ModalData::eigenvalues: unit
/// density and Young's modulus, unit volume) and its distance to the query (Match::distance, ≥ 0).
struct SpectrumSample {
  const Eigen::VectorXd* eigenvalues = nullptr;
  double distance = 0.0;
};

/// How much farther than the nearest a sample may be and still count in blendSpectra: a sample farther
/// off is another kind of shape, not one of the entries around the query, and an entry that is the query's
/// own shape (its learned entry, say: at a distance near 0) then answers alone. On the benchmark the
/// second-nearest of a fracture fragment or a real object lay a median 1.0-1.2 and at most 2.8 times as
/// far as the nearest.
inline constexpr double kSpectrumReach = 2.0;

/// The spectrum of a query from its k nearest entries (k-nearest-neighbour regression; docs/accuracy.md,
/// "The nearest tier's spectrum"): per mode, the weighted geometric mean of the samples' eigenvalues of
/// that rank, over the samples within kSpectrumReach times the nearest's distance that have the mode,
/// with weights 1/distance. The database samples shapes and proportions on a grid, and a query falls
/// between its entries: one entry's spectrum carries that entry's own offset from the query, several
/// nearby ones' average theirs out. A sample at distance 0 is the query's own shape and answers alone
/// (samples at distance 0 share the weight equally). As many modes as the first sample has (the
/// nearest: its mode shapes are the answer's). `weights`, if given, receives each sample's weight (0
/// for those out of reach; they sum to 1). Precondition: samples is not empty, the first is the nearest,
/// every eigenvalue is finite and > 0, every distance finite and ≥ 0.
Eigen::VectorXd blendSpectra(std::span<const SpectrumSample> samples, std::vector<double>* weights = nullptr);

}  // namespace shapedb::core
