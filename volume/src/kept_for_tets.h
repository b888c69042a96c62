#pragma once
// What a plan (volume::ModalPlan, volume::MorphPlan) keeps: one value worked out from a tet mesh's
// connectivity, served again only for the same tets. Private to the volume module.

#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include <shapedb/core/physics.h>

namespace shapedb::volume::detail {

/// A value made for a tet mesh's connectivity (its tets and node count) and a `variant` of it (the element
/// order a symbolic analysis is of, say), kept once: the first value kept stays, and it is served only for
/// the same tets and variant. Thread-safe.
template <class T>
class KeptForTets {
 public:
  /// The value, where it was made for `mesh`'s tets and `variant`; null otherwise.
  std::shared_ptr<const T> find(const core::TetMesh& mesh, int variant = 0) const {
    const std::lock_guard lock(mMutex);
    return mValue && variant == mVariant && mesh.nodeCount() == mNodeCount && mesh.tets == mTets ? mValue
                                                                                                 : nullptr;
  }
  /// Keeps `made`, made for `mesh`'s tets and `variant`, unless a value is kept already.
  void keep(const core::TetMesh& mesh, std::shared_ptr<const T> made, int variant = 0) {
    const std::lock_guard lock(mMutex);
    if (mValue) return;
    mTets = mesh.tets;
    mNodeCount = mesh.nodeCount();
    mVariant = variant;
    mValue = std::move(made);
  }
  bool ready() const {
    const std::lock_guard lock(mMutex);
    return mValue != nullptr;
  }

 private:
  mutable std::mutex mMutex;
  std::vector<core::TetMesh::Tet> mTets;
  std::size_t mNodeCount = 0;
  int mVariant = 0;
  std::shared_ptr<const T> mValue;
};

}  // namespace shapedb::volume::detail
