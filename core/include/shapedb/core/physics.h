#pragma once

// The physical data a database entry carries (paper §3.1), in the entry's canonical frame: unit volume,
// centre of mass at the origin, principal axes on x, y, z. Everything is stored for unit density and unit
// Young's modulus; adaptation (core/adapt.h) scales it to the query's size and material.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

/// A tetrahedral mesh: nodes and positively oriented tets (det[b−a, c−a, d−a] > 0). Plain value type.
struct TetMesh {
  using Tet = std::array<std::uint32_t, 4>;
  std::vector<Vec3> nodes;
  std::vector<Tet> tets;
  std::size_t nodeCount() const { return nodes.size(); }
  std::size_t tetCount() const { return tets.size(); }
};

/// Signed volume of tet t: det[b−a, c−a, d−a] / 6.
double tetVolume(const TetMesh& mesh, std::size_t t);

/// Linear shape functions of tet t: the gradients of N_0..N_3 (columns, constant over the tet) and the
/// signed volume.
struct TetGradients {
  Eigen::Matrix<double, 3, 4> gradients;
  double volume = 0.0;
};
TetGradients tetGradients(const TetMesh& mesh, std::size_t t);
/// The same for a tet given by its four corners.
TetGradients tetGradients(const std::array<Vec3, 4>& corners);

/// The volume at or under which a tet of `mesh` is numerically flat, its stiffness garbage: 1e-15 of the
/// cube of the nodes' largest extent.
double flatTetVolume(const TetMesh& mesh);

/// Checks indices, finiteness and that every tet has a volume above flatTetVolume.
/// Errors: kEmptyMesh, kIndexOutOfRange, kNonFinite, kDegenerateFace (a flat or inverted tet).
Status validateTetMesh(const TetMesh& mesh);

/// Exact mass properties of the solid made of the tets (volume integrals, tet by tet), in the mesh's
/// frame. `area` is left 0: a tet mesh knows no surface. Preconditions: validateTetMesh passed.
MassProperties computeTetMassProperties(const TetMesh& mesh, double density = 1.0);

/// A face of a tet mesh that belongs to one tet only: its nodes (mesh indices), wound outward, and that tet.
struct BoundaryFace {
  std::array<std::uint32_t, 3> nodes;
  std::uint32_t tet = 0;
};
/// Every boundary face of a tet mesh, ordered by sorted node triple (deterministic).
std::vector<BoundaryFace> boundaryFaces(const TetMesh& mesh);
/// The boundary of a tet mesh: every face that belongs to one tet only, wound outward, over the nodes
/// it uses (renumbered). For a conforming mesh of a solid, a closed surface.
TriangleMesh boundarySurface(const TetMesh& mesh);

/// How many pieces the tets make when two tets are joined only through a face they share: 1 for a solid
/// meshed properly, 0 for no tets. Tets held to the rest by an edge or a node alone turn about it at no
/// strain, a mechanism that the modes of the mesh would ring as a near-zero frequency beyond the six rigid
/// motions.
std::size_t faceConnectedPieces(const TetMesh& mesh);

/// Modes of vibration of the free body (K φ = λ M φ) for unit density and unit Young's modulus at the
/// stated Poisson ratio, in the canonical (unit-volume) frame: ω' = √λ rad/s. The six rigid modes are
/// dropped. Mode i is column i of `shapes`, 3 values per node (x, y, z), M-orthonormal: φᵢᵀ M φⱼ = δᵢⱼ.
struct ModalData {
  double poissonRatio = 0.3;
  Eigen::VectorXd eigenvalues;  ///< λ, ascending, > 0
  Eigen::MatrixXd shapes;       ///< 3·nodes × modes
  /// The six smallest eigenvalues found (the rigid modes), relative to eigenvalues[0]: near zero.
  std::array<double, 6> rigidEigenvalues{};
  std::size_t modeCount() const { return static_cast<std::size_t>(eigenvalues.size()); }
  /// ω'ᵢ / 2π, Hz, for unit density, Young's modulus and volume.
  Eigen::VectorXd frequenciesHz() const;
};

/// Rayleigh damping C = αM + βK: the damping ratio of a mode of angular frequency ω (rad/s) is
/// ζ = (α/ω + βω) / 2.
struct RayleighDamping {
  double alpha = 0.0;  ///< 1/s
  double beta = 0.0;   ///< s
  double dampingRatio(double omega) const { return 0.5 * (alpha / omega + beta * omega); }
};

/// One solid of a collision compound, in the canonical frame. A box and a capsule are aligned with their
/// own `rotation` (columns: the local axes); a capsule's segment runs along its local z.
struct CollisionShape {
  enum class Type : std::uint8_t { kSphere, kBox, kCapsule };
  Type type = Type::kSphere;
  Vec3 center = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
  Vec3 halfExtents = Vec3::Zero();  ///< box only
  double radius = 0.0;              ///< sphere, capsule
  double halfLength = 0.0;          ///< capsule: half the length of its axis segment
  /// True when `p` (canonical frame) lies inside the solid.
  bool contains(const Vec3& p) const;
  double volume() const;
  /// Half the extent of its axis-aligned bounding box along x, y and z (canonical frame), about `center`.
  Vec3 halfSpan() const;
};

/// "sphere", "box", "capsule".
const char* toString(CollisionShape::Type type);

/// A union of simple solids approximating the entry's volume, with how well it does: coverage = the
/// fraction of the volume inside the compound, overshoot = the compound's volume outside the solid as a
/// fraction of the solid's volume (both measured on the same voxel sampling).
struct CollisionCompound {
  std::vector<CollisionShape> shapes;
  double coverage = 0.0;
  double overshoot = 0.0;
};

/// What a sound synthesizer needs besides the mode shapes: the frequencies for unit material and
/// volume, and the damping model the database was built with.
struct SoundData {
  Eigen::VectorXd frequenciesHz;
  RayleighDamping damping;
};

/// Everything precomputed for one entry.
struct PhysicalData {
  TetMesh tetMesh;
  MassProperties massProperties;  ///< of the tet mesh, unit density
  ModalData modes;
  CollisionCompound collision;
  SoundData sound;
};

}  // namespace shapedb::core
