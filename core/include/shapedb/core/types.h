#pragma once

#include <Eigen/Dense>

namespace shapedb::core {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;

/// Applies the homogeneous transform dstFromSrc (last row 0 0 0 1) to a point in src.
inline Vec3 transformPoint(const Mat4& dstFromSrc, const Vec3& pSrc) {
  return dstFromSrc.topLeftCorner<3, 3>() * pSrc + dstFromSrc.topRightCorner<3, 1>();
}

}  // namespace shapedb::core
