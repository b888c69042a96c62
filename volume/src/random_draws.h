#pragma once

#include <Eigen/Geometry>

#include <shapedb/core/types.h>

namespace shapedb::volume::detail {

// The language leaves the order in which a call's arguments are evaluated to the compiler: GCC takes
// them last first, Clang first to last. Vec3(draw(), draw(), draw()) therefore drew the same numbers into
// other components in each, and a catalog (or a fracture of one seed) built by one was another shape in
// the other. These draw in one order in every build: the last component first, as GCC did, so that the
// catalogs and fractures made before keep their shapes.

/// (x, y, z) of three draws, z drawn first.
template <class Draw>
core::Vec3 drawVector(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  return {x, y, z};
}

/// The quaternion (w, x, y, z) of four draws, z drawn first and w last.
template <class Draw>
Eigen::Quaterniond drawQuaternion(Draw&& draw) {
  const double z = draw();
  const double y = draw();
  const double x = draw();
  const double w = draw();
  return {w, x, y, z};
}

}  // namespace shapedb::volume::detail
