#pragma once

// The one material type of shapedb: the database's FEM runs on the unit material, and adaptation carries
// its results to a real one (paper §5: frequencies scale as √(E/ρ)).

#include <span>
#include <string>
#include <string_view>

#include <shapedb/core/result.h>

namespace shapedb::core {

/// An isotropic linear elastic material, SI units.
struct Material {
  std::string name;            ///< a preset's name, "unit" or "custom"
  double density = 0.0;        ///< ρ, kg/m³
  double youngsModulus = 0.0;  ///< E, Pa
  double poissonRatio = 0.0;   ///< ν, in (−1, 0.5)
};

/// ρ = E = 1 (and ν = 0.3 unless given): what database entries are computed for.
Material unitMaterial(double poissonRatio = 0.3);

/// The Poisson ratios an isotropic linear elastic solid can have, (−1, 0.5): the one check of ν in
/// shapedb (materials, the FEM, build parameters, stored modes).
bool validPoissonRatio(double nu);

/// steel, aluminium, glass, wood, rubber, concrete: textbook room-temperature values (wood: along the
/// grain, as an isotropic stand-in; rubber: small-strain modulus).
std::span<const Material> materialPresets();
/// A preset by name (case-insensitive; "aluminum" also accepted). Errors: kInvalidArgument naming the
/// presets.
Result<Material> materialPreset(std::string_view name);
/// Errors: kInvalidArgument if ρ or E is not finite and positive or ν is outside (−1, 0.5).
Status validateMaterial(const Material& material);

}  // namespace shapedb::core
