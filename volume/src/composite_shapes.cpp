#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include <shapedb/core/primitives.h>
#include <shapedb/core/self_intersection.h>

#include "family_shapes.h"
#include "random_draws.h"

namespace shapedb::volume::detail {
namespace {

using core::TriangleMesh;
using core::Vec3;

constexpr int kSegments = 32;  ///< of every primitive: the level set's voxels, not these, set the detail
constexpr int kAttempts = 16;  ///< draws before a family gives up on an index (never seen to be needed)

/// `mesh` rotated by `rotation`, then moved to `centre`.
TriangleMesh placed(const TriangleMesh& mesh, const Eigen::Matrix3d& rotation, const Vec3& centre) {
  core::Mat4 meshFromPrimitive = core::Mat4::Identity();
  meshFromPrimitive.topLeftCorner<3, 3>() = rotation;
  meshFromPrimitive.topRightCorner<3, 1>() = centre;
  return core::transformed(mesh, meshFromPrimitive);
}

/// A capsule of radius r whose axis runs from `from` along the unit `direction` for `length`.
TriangleMesh limb(const Vec3& from, const Vec3& direction, double length, double r) {
  const Eigen::Matrix3d rotation =
      Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), direction).toRotationMatrix();
  return placed(core::makeCapsule(r, length, kSegments, kSegments / 4), rotation,
                from + 0.5 * length * direction);
}

TriangleMesh moved(const TriangleMesh& mesh, const Vec3& centre) {
  return placed(mesh, Eigen::Matrix3d::Identity(), centre);
}

double logUniform(std::mt19937_64& rng, double lo, double hi) {
  return lo * std::exp(std::log(hi / lo) * std::uniform_real_distribution<double>(0.0, 1.0)(rng));
}

/// Draws `make` (a list of terms and the thinnest part) until its solid is one closed piece whose surface
/// does not pass through itself: simplified down to a few hundred triangles, a thin limb's or ear's level
/// set can fold into its neighbour (limbed-00114 of the sweep did, and TetGen crashed on it).
template <typename Make>
Result<TriangleMesh> drawCsg(Make make, std::size_t maxTriangles) {
  Error last{ErrorCode::kNotClosed, ""};
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    auto [terms, thinnest] = make();
    Result<TriangleMesh> mesh = meshCsg(terms, thinnest, maxTriangles);
    if (mesh && core::findSelfIntersections(*mesh).empty()) return mesh;
    last = mesh ? Error{ErrorCode::kSelfIntersecting, "the simplified surface passes through itself"}
                : mesh.error();
  }
  return last;
}

}  // namespace

Result<TriangleMesh> makeLimbedShape(int limbs, double length, double radius, std::mt19937_64& rng,
                                     std::size_t maxTriangles) {
  // An ellipsoidal body (1, a, b) along x; limbs in pairs along its underside (legs, splayed), or the first
  // pair out to the sides (arms); an odd limb is a tail. Then maybe a head in front, with ears.
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return drawCsg(
      [&] {
        const double a = 0.4 + 0.35 * unit(rng), b = 0.35 + (a - 0.35) * unit(rng);
        std::vector<CsgTerm> terms{{core::makeUvEllipsoid(Vec3(1.0, a, b), kSegments, kSegments / 2), false}};
        double thinnest = 2.0 * radius;
        const int pairs = limbs / 2;
        const bool arms = unit(rng) < 0.3;
        for (int p = 0; p < pairs; ++p) {
          const double x = pairs == 1 ? 0.0 : -0.6 + 1.2 * p / (pairs - 1);
          const double splay = 0.5 * unit(rng);
          for (const double side : {-1.0, 1.0}) {
            const Vec3 from(x, side * 0.45 * a, -0.35 * b);
            const Vec3 direction = arms && p == 0 ? Vec3(0.2 * (unit(rng) - 0.5), side, -0.3).normalized()
                                                  : Vec3(0.0, side * std::sin(splay), -std::cos(splay));
            terms.push_back({limb(from, direction, length, radius), false});
          }
        }
        if (limbs % 2 == 1) {
          terms.push_back(
              {limb(Vec3(-0.7, 0, 0), Vec3(-1.0, 0, 0.5 + unit(rng)).normalized(), length, 0.7 * radius),
               false});
          thinnest = std::min(thinnest, 1.4 * radius);
        }
        if (unit(rng) < 0.75) {
          const double head = 0.25 + 0.2 * unit(rng);
          const Vec3 centre(1.0 + 0.3 * head, 0.0, 0.4 * b);
          terms.push_back(
              {moved(core::makeUvEllipsoid(Vec3::Constant(head), kSegments, kSegments / 2), centre), false});
          if (unit(rng) < 0.5) {
            const double ear = std::max(0.1, 0.3 * head);
            for (const double side : {-1.0, 1.0})
              terms.push_back(
                  {limb(centre, Vec3(-0.2, 0.5 * side, 1.0).normalized(), 1.3 * head, 0.5 * ear), false});
            thinnest = std::min(thinnest, ear);
          }
        }
        return std::pair{terms, thinnest};
      },
      maxTriangles);
}

Result<TriangleMesh> makeUnionShape(int count, std::mt19937_64& rng, std::size_t maxTriangles) {
  // Boxes, ellipsoids, cylinders and capsules of random proportions and orientations, each centred inside
  // the one before it, so that the union is one piece.
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  return drawCsg(
      [&] {
        std::vector<CsgTerm> terms;
        double thinnest = 2.0;
        Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
        Vec3 centre = Vec3::Zero(), half = Vec3::Ones();  // the last primitive's centre and half-extents
        for (int i = 0; i < count; ++i) {
          const double scale = i == 0 ? 1.0 : 0.4 + 0.6 * unit(rng);
          const double depth = logUniform(rng, 0.3, 1.0);  // drawn first, as GCC did (random_draws.h)
          const Vec3 size = scale * Vec3(1.0, logUniform(rng, 0.3, 1.0), depth);
          if (i > 0) {
            const Vec3 inside = detail::drawVector([&] { return 2.0 * unit(rng) - 1.0; });
            const Vec3 step = 0.5 * inside.cwiseProduct(half);  // rotated written out, as transformPoint
            centre += rotation.col(0) * step.x() + rotation.col(1) * step.y() + rotation.col(2) * step.z();
            rotation = detail::drawQuaternion([&] { return normal(rng); }).normalized().toRotationMatrix();
          }
          TriangleMesh primitive;
          switch (static_cast<int>(4.0 * unit(rng))) {
            case 0:
              primitive = core::makeBox(2.0 * size);
              break;
            case 1:
              primitive = core::makeUvEllipsoid(size, kSegments, kSegments / 2);
              break;
            case 2:
              primitive =
                  core::transformed(core::makeCylinder(1.0, 2.0 * size.z(), kSegments),
                                    Eigen::Affine3d(Eigen::Scaling(size.x(), size.y(), 1.0)).matrix());
              break;
            default: {
              const double r = std::min(size.x(), size.y());
              primitive = core::makeCapsule(r, 2.0 * size.z(), kSegments, kSegments / 4);
              terms.push_back({placed(primitive, rotation, centre), false});
              half = Vec3(r, r, size.z() + r);  // the next centre within half of these stays inside
              thinnest = std::min(thinnest, 2.0 * r);
              continue;
            }
          }
          terms.push_back({placed(primitive, rotation, centre), false});
          half = size;
          thinnest = std::min(thinnest, 2.0 * size.minCoeff());
        }
        return std::pair{terms, thinnest};
      },
      maxTriangles);
}

}  // namespace shapedb::volume::detail
