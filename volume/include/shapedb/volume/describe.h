#pragma once

#include <memory>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/orientation.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume {

/// Computes shape descriptors (paper §4) of a mesh in its canonical frame, on a dense OpenVDB grid
/// (tools::Dense, N³ cells) that accumulates, per cell, the surface area (or vertex count) and its first
/// moment.
///
/// Area sampling clips every triangle exactly against the cells, so a cell receives exactly the part
/// of the surface inside it: a re-tessellation of the same surface (midpoint subdivision, say) gets the
/// same descriptor up to round-off. Cell coordinates are snapped to 2⁻²⁰ of a cell before binning, so a
/// face lying on a cell plane (a box's, in its canonical frame) lands on the same side whatever
/// round-off the rigid transform left on it.
///
/// One Describer per thread: it keeps its scratch (the grid, vertex buffers) between calls so that
/// describing allocates nothing once warm. Not thread-safe; cheap to create (the grid, 32·N³ bytes, is
/// allocated by the first describe).
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

/// The oracle of Describer::describe with area sampling: every triangle cut against each cell of its
/// range on its own (the cell's interior planes; the border cells reach out to infinity) by the plainest
/// polygon clipping, O(cells) per triangle, no shortcuts. The same vertices and the same side for surface
/// on a cell plane; the same descriptor up to round-off. For tests. Errors: as describe, and
/// kInvalidArgument for a moment descriptor or vertex sampling.
Result<core::Descriptor> describeReference(const core::TriangleMesh& mesh,
                                           const core::Normalization& normalization,
                                           const core::DescriptorOptions& options,
                                           const core::Mat3& orientation = core::Mat3::Identity());

/// Checks options: grid size in [2, kMaxGridSize], minCellArea finite and in [0, 1).
Status validateDescriptorOptions(const core::DescriptorOptions& options);

}  // namespace shapedb::volume
