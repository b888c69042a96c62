#pragma once
// Modal sound synthesis (the paper's first application): the sound of an impact on an object from its
// adapted modes. Each mode rings as a damped sinusoid at its frequency, excited by the impulse through
// the linking weights at the impact point (van den Doel & Pai; O'Brien et al.).
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/adapt.h>
#include <shapedb/core/result.h>
#include <shapedb/core/spatial.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::core {

struct ImpactSoundOptions {
  int sampleRate = 44100;         ///< Hz, 8,000 to 192,000
  double seconds = 2.0;           ///< length of the sound, > 0, ≤ 60
  double maxFrequencyHz = 20000;  ///< modes above this (or above the Nyquist frequency) are left out
};

struct ImpactSound {
  /// Mono samples at sampleRate, scaled so that the loudest is ±0.9 (a level for a file, not a
  /// physical pressure): the sum over the audible modes of their velocity after a unit impulse,
  /// gᵢ e^(−ζᵢωᵢt) (cos ωd t − ζᵢωᵢ/ωd sin ωd t), gᵢ = φᵢ(impact) · direction. Radiation efficiency
  /// is not modelled.
  std::vector<float> samples;
  int sampleRate = 0;
  std::vector<int> modes;         ///< the modes that sound (indices into the physics' modes)
  Eigen::VectorXd frequenciesHz;  ///< theirs, undamped
  Eigen::VectorXd gains;          ///< theirs, gᵢ (m/s per N·s)
  double scale = 0.0;             ///< samples = scale · (the physical modal velocity sum, m/s per N·s)
};

/// Where an impact strikes a surface: a vertex, and the direction of the blow, its inward unit normal
/// (the area-weighted normal of its triangles, reversed; zero where those cancel).
struct ImpactPoint {
  std::size_t vertex = 0;
  Vec3 direction = Vec3::Zero();
};

/// The vertex of `mesh` nearest `near`, or without it the one farthest from `center` (the centre of mass,
/// say: a corner or a tip, which excites most modes). Errors: kEmptyMesh (no vertex).
Result<ImpactPoint> chooseImpact(const TriangleMesh& mesh, const Vec3& center,
                                 const std::optional<Vec3>& near = std::nullopt);

/// The sound of a unit impulse along `direction` (normalized here) at `at`, a point located in the
/// adapted tets (a vertex's SurfaceLink location). Errors: kInvalidArgument (options, a zero
/// direction, a location outside the tet mesh's indices, or no mode below the frequency limit: the
/// message gives the lowest frequency).
Result<ImpactSound> synthesizeImpact(const AdaptedPhysics& physics, const TetLocation& at,
                                     const Vec3& direction, const ImpactSoundOptions& options = {});

}  // namespace shapedb::core
