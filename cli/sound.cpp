// shapedb sound: the sound of an impact on a mesh that has no physical data, from the modes of its best
// match adapted to it (the paper's first application).

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/sound.h>
#include <shapedb/io/audio.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>

#include "commands.h"
#include "material_flags.h"

namespace shapedb::cli {
namespace {

struct SoundCommandOptions {
  MeshLoadFlags load;
  std::string database;
  std::string mesh;
  std::string out;
  std::string descriptor = "centroid-voxel";
  std::vector<double> impact;
  MaterialFlags material;
  core::ImpactSoundOptions sound;
};

int runSound(const SoundCommandOptions& o, const CLI::App& app) {
  const std::optional<core::Material> material = resolveMaterial(o.material, app);
  if (!material) return kExitUsage;
  Result<io::LoadedMesh> loaded = loadMeshFile(o.mesh, o.load);
  if (!loaded) {
    printError(loaded.error().message);
    return kExitInputError;
  }
  io::Database::OpenOptions open;
  open.descriptors = {*core::parseDescriptorKind(o.descriptor)};
  auto db = io::Database::open(o.database, open);
  if (!db) {
    printError(db.error().message);
    return kExitInputError;
  }
  io::QueryOptions query;
  query.descriptor = *core::parseDescriptorKind(o.descriptor);
  query.material = *material;
  query.fidelity = false;
  Result<io::QueryResult> r = db->query(loaded->mesh, query);
  if (!r) {
    printError(o.mesh + ": " + r.error().message + flagHint(r.error()));
    return kExitInputError;
  }
  if (r->matches.empty() || !r->physics) {
    printError(o.database + ": the database gave no match");
    return kExitInputError;
  }

  // The impact: the vertex nearest --impact, or by default the one farthest from the centre of mass.
  const core::TriangleMesh& mesh = loaded->mesh;
  std::optional<core::Vec3> near;
  if (o.impact.size() == 3) near = core::Vec3(o.impact[0], o.impact[1], o.impact[2]);
  Result<core::ImpactPoint> impact = core::chooseImpact(mesh, r->massProperties.centerOfMass, near);
  if (!impact) {
    printError(o.mesh + ": " + impact.error().message);
    return kExitInputError;
  }
  const std::size_t vertex = impact->vertex;
  Result<core::ImpactSound> sound =
      core::synthesizeImpact(*r->physics, r->link.locations[vertex], impact->direction, o.sound);
  if (!sound) {
    printError(o.mesh + ": " + sound.error().message);
    return kExitInputError;
  }
  if (Status st = io::saveWav(sound->samples, sound->sampleRate, o.out); !st) {
    printError(st.error().message);
    return kExitInputError;
  }
  const core::Vec3& p = mesh.vertices[vertex];
  std::printf("%s: matched %s; %s; struck at vertex %zu (%.4g, %.4g, %.4g) m\n", o.mesh.c_str(),
              r->answeredMatch().entry->name.c_str(), material->name.c_str(), vertex, p.x(), p.y(), p.z());
  std::printf("%zu of %lld modes ring:", sound->modes.size(),
              static_cast<long long>(r->physics->eigenvalues.size()));
  for (Eigen::Index i = 0; i < sound->frequenciesHz.size(); ++i)
    std::printf(" %.1f", sound->frequenciesHz[i]);
  std::printf(" Hz\nwrote %s (%.3g s at %d Hz)\n", o.out.c_str(), o.sound.seconds, sound->sampleRate);
  return kExitOk;
}

}  // namespace

Command addSoundCommand(CLI::App& parent) {
  auto o = std::make_shared<SoundCommandOptions>();
  CLI::App* app = parent.add_subcommand(
      "sound",
      "The sound of an impact on a mesh (a WAV file): the mesh is queried, its best match's modes adapted\n"
      "to its size and material, and a unit impulse at the impact point (the vertex nearest --impact, or\n"
      "the one farthest from the centre of mass) along the inward normal rings every mode below 20 kHz as\n"
      "a damped sinusoid (the database's Rayleigh damping), excited through the linking weights there.\n"
      "The level is normalized (peak 0.9); radiation efficiency is not modelled.");
  app->add_option("DB", o->database, "Database file (from shapedb build)")->required();
  app->add_option("MESH", o->mesh, "Closed surface mesh (.obj, .ply, .off, .stl, .gltf, .glb, .fbx, .dae)")
      ->required();
  addMeshLoadFlags(*app, o->load);
  app->add_option("--out", o->out, "WAV file to write (16-bit PCM, mono)")->required();
  app->add_option("--impact", o->impact, "X,Y,Z: strike the vertex nearest this point (mesh frame, metres)")
      ->delimiter(',')
      ->expected(3);
  app->add_option("--seconds", o->sound.seconds, "Length of the sound")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 60.0));
  app->add_option("--sample-rate", o->sound.sampleRate, "Samples per second")
      ->capture_default_str()
      ->check(CLI::Range(8000, 192000));
  app->add_option("--descriptor", o->descriptor, "Descriptor used to match")
      ->capture_default_str()
      ->check(CLI::IsMember({"moment", "voxel", "centroid-voxel"}));
  addMaterialFlags(*app, o->material);
  return {app, [o, app] { return runSound(*o, *app); }};
}

}  // namespace shapedb::cli
