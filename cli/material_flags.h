#pragma once

// The material flags shared by the subcommands that adapt physical data: a preset, or a custom
// density, Young's modulus and Poisson ratio.

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include <shapedb/core/adapt.h>

namespace shapedb::cli {

struct MaterialFlags {
  std::string preset = "steel";
  double density = 0.0, youngs = 0.0, poisson = 0.0;
};

/// Adds --material, --density, --youngs and --poisson to `app`.
void addMaterialFlags(CLI::App& app, MaterialFlags& flags);

/// The material the flags name, after parsing. On a bad combination or value prints the reason and
/// returns nothing (a usage error).
std::optional<core::Material> resolveMaterial(const MaterialFlags& flags, const CLI::App& app);

}  // namespace shapedb::cli
