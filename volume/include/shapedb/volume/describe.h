#pragma once

#include <memory>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/orientation.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

/// Computes shape descriptors (paper §4) of a mesh in its canonical frame, on a sparse OpenVDB grid
/// that accumulates, per cell, the surface area (or vertex count) and its first moment.
///
/// Area sampling clips every triangle exactly against the cells, so a cell receives exactly the part
/// of the surface inside it: a re-tessellation of the same surface (midpoint subdivision, say) gets the
/// same descriptor up to round-off. Cell coordinates are snapped to 2⁻²⁰ of a cell before binning, so a
/// face lying on a cell plane (a box's, in its canonical frame) lands on the same side whatever
/// round-off the rigid transform left on it.
///
/// One Describer per thread: it keeps its scratch (the grid's nodes, vertex buffers) between calls so
/// that describing allocates nothing once warm. Not thread-safe; cheap to create.
class Describer {
 public:
  explicit Describer(const core::DescriptorOptions& options = {});
  ~Describer();
  Describer(Describer&&) noexcept;
  Describer& operator=(Describer&&) noexcept;

  const core::DescriptorOptions& options() const { return mOptions; }

  /// The descriptor of `mesh` in the frame orientation · canonicalFromMesh (orientation: a rotation,
  /// candidateFromCanonical; identity for the canonical frame itself). `normalization` comes from
  /// core::normalize on the same mesh.
  /// Errors: kInvalidArgument for options out of range or a mesh without extent; kIndexOutOfRange,
  /// kNonFinite for a mesh that validateMesh would refuse.
  Result<core::Descriptor> describe(const core::TriangleMesh& mesh, const core::Normalization& normalization,
                                    const core::Mat3& orientation = core::Mat3::Identity());

  /// One descriptor per orientation candidate (core::orientationCandidates), the canonical frame
  /// first; each records its rotation in Descriptor::orientation. Moment descriptors do not depend
  /// on the orientation: one.
  Result<std::vector<core::Descriptor>> describeCandidates(const core::TriangleMesh& mesh,
                                                           const core::Normalization& normalization,
                                                           const core::OrientationOptions& orientation = {});

 private:
  struct Impl;
  core::DescriptorOptions mOptions;
  std::unique_ptr<Impl> mImpl;
};

/// One-off form of Describer::describe. Thread-safe (pure function).
Result<core::Descriptor> describe(const core::TriangleMesh& mesh, const core::Normalization& normalization,
                                  const core::DescriptorOptions& options = {});

/// Checks options: grid size in [2, kMaxGridSize], minCellArea finite and in [0, 1).
Status validateDescriptorOptions(const core::DescriptorOptions& options);

}  // namespace shapedb::volume
