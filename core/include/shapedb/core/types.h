#pragma once

#include <Eigen/Dense>

namespace shapedb::core {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;

/// Applies the homogeneous transform dstFromSrc (last row 0 0 0 1) to a point in src. Written out, so that
/// it rounds alike in every build: Eigen's product fuses multiply-adds where the processor has them
/// (-march=native), and the catalog's shapes, placed with this, must be the same bits everywhere.
inline Vec3 transformPoint(const Mat4& dstFromSrc, const Vec3& pSrc) {
  const Mat4& m = dstFromSrc;
  const Vec3& p = pSrc;
  return {m(0, 0) * p.x() + m(0, 1) * p.y() + m(0, 2) * p.z() + m(0, 3),
          m(1, 0) * p.x() + m(1, 1) * p.y() + m(1, 2) * p.z() + m(1, 3),
          m(2, 0) * p.x() + m(2, 1) * p.y() + m(2, 2) * p.z() + m(2, 3)};
}

}  // namespace shapedb::core
