#pragma once

#include <array>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/volume/collision.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume {

/// TetGen's bounds for an entry whose modes use `order` elements. Quadratic tets need much coarser meshes
/// for the same accuracy, and cost ~10x as much per tet: q3 and 1/100 of the volume (a third of the tet
/// size gives frequencies a median 0.16 % and at most 2 % lower on the entries measured so far:
/// docs/accuracy.md), against q1.5 and 1/600
/// for linear ones (whose frequencies still come out high in bending).
TetrahedralizeOptions entryMeshing(ElementOrder order);

/// Everything that decides what a database entry holds. A database stores these with its entries: two
/// entries built with different options are not comparable. The defaults are the default build's:
/// quadratic tets at entryMeshing(kQuadratic).
struct EntryOptions {
  /// Grid size, sampling and fill threshold of the voxel descriptors (`kind` is ignored: an entry gets
  /// all three).
  core::DescriptorOptions descriptor;
  TetrahedralizeOptions tetgen = entryMeshing(ElementOrder::kQuadratic);
  ModalOptions modal;  ///< modes, elements (quadratic) and Poisson ratio; E = ρ = 1 always
  CollisionOptions collision;
  core::RayleighDamping damping{
      .alpha = 2.0, .beta = 1e-6};  ///< for the sound data: α (1/s), β (s), applied to adapted frequencies
};

/// `options` with the modal analysis on `order` elements and the TetGen bounds that go with them
/// (entryMeshing); the wall bound, which no order sets, is kept.
EntryOptions withElements(EntryOptions options, ElementOrder order);

/// Wall time of each stage of computeEntry, seconds.
struct StageTimes {
  double normalize = 0.0;
  double tetrahedralize = 0.0;
  double describe = 0.0;
  double modes = 0.0;
  double collision = 0.0;
  double total() const { return normalize + tetrahedralize + describe + modes + collision; }
};

/// A database entry computed from its surface, before it is stored.
struct EntryData {
  core::MassProperties surfaceMassProperties;  ///< of the input surface, unit density, its own frame
  core::Normalization normalization;           ///< input frame → canonical frame
  /// Canonical descriptors, indexed by DescriptorKind: moment, voxel, centroid-voxel.
  std::array<core::Descriptor, 3> descriptors;
  core::PhysicalData physics;  ///< canonical frame, unit density and Young's modulus
  StageTimes times;
};

/// The offline pipeline for one shape (paper §3.1): exact mass properties → normalize → the surface in
/// its canonical frame → TetGen (guarded unless options.tetgen says otherwise) → mass properties of the
/// tets, checked against the surface's (volume to 1e-9) → the three descriptors → FEM and modes → collision
/// compound → sound data. TetGen meshes the surface as given; its nodes are then mapped to the canonical
/// frame. Thread-safe (no shared state); the caller parallelizes over entries.
/// Errors: whichever stage failed, its message prefixed with the stage ("tetrahedralize: ...").
Result<EntryData> computeEntry(const core::TriangleMesh& surface, const EntryOptions& options);

}  // namespace shapedb::volume
