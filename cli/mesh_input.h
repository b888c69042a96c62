#pragma once

// Loading a mesh and putting it in its canonical frame, shared by the subcommands that take a mesh.

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/io/mesh_io.h>

#include "commands.h"

namespace shapedb::cli {

/// The flags that decide which meshes are accepted, and the density for mass properties.
struct MeshInputOptions {
  double density = 1000.0;
  bool approximate = false;
  bool flipInsideOut = false;
  bool allowDegenerate = false;
  MeshLoadFlags load;
};

/// Adds --density, --approximate, --flip-inside-out, --allow-degenerate and the load flags to `app`.
void addMeshInputFlags(CLI::App& app, MeshInputOptions& options);

/// A mesh loaded, with its mass properties and canonical frame.
struct MeshInput {
  io::LoadedMesh loaded;
  core::MassProperties massProperties;
  core::Normalization normalization;
};

/// Loads `path` and normalizes it; on failure prints "shapedb: <path>: <problem>[; hint]" and returns
/// nothing.
std::optional<MeshInput> loadMeshInput(const std::string& path, const MeshInputOptions& options);

}  // namespace shapedb::cli
