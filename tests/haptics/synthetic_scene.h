#pragma once

// Scenes and augmentation the haptic tests can make without a database: boxes whose "physical data"
// are a tet grid of the box with smooth, lumped-mass-normalized mode shapes. Enough to exercise the
// loop's contact, dynamics and concurrency on real geometry, in a test that builds from core alone.

#include <vector>

#include <shapedb/haptics/loop.h>

namespace shapedb::haptics::test {

/// An axis-aligned box object of side `size` centred at `center`.
SceneObject boxObject(const std::string& name, const core::Vec3& center, double size);

/// `count` boxes of side `size` in a row along x, `spacing` apart, centred at y = z = 0.
std::vector<SceneObject> boxRow(int count, double size, double spacing);

/// Augments a box object (one made by boxObject): 3 × 3 × 3 cubes of six tets each, `modes` modes of
/// 200, 400, ... Hz, density 1000 kg/m³, Rayleigh damping α = 2/s, β = 2e-6 s; a one-box compound.
Result<AugmentedObject> augmentBox(const SceneObject& object, int modes = 6);

}  // namespace shapedb::haptics::test
