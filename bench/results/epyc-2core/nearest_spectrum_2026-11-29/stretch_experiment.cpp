// Scratch experiment (not for commit): the nearest entry stretched to the query's second moments,
// its modes computed exactly on the stretched quadratic tets. Prints per mesh: entry, f1 nearest,
// f1 stretched (as is and volume-normalized), stretch factors.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/physics.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/modal.h>

using namespace shapedb;
using core::Mat3;
using core::Vec3;

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  auto db = io::Database::open(argv[1]);
  if (!db) {
    std::fprintf(stderr, "%s\n", db.error().message.c_str());
    return 1;
  }
  std::printf("shape,entry,f1_nearest,f1_stretched,f1_stretched_vol,ax,ay,az,det\n");
  for (int i = 2; i < argc; ++i) {
    auto mesh = io::loadMesh(argv[i]);
    if (!mesh) {
      std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
      continue;
    }
    io::QueryOptions options;
    options.fidelity = false;
    options.link = false;
    auto r = db->query(mesh->mesh, options);
    if (!r || !r->physics) {
      std::fprintf(stderr, "%s: query failed\n", argv[i]);
      continue;
    }
    const core::PhysicalData& entry = *r->entryPhysics;
    const Mat3& O = r->answeredMatch().match.orientation;
    const core::MassProperties tm = core::computeTetMassProperties(entry.tetMesh);
    const Mat3 body = core::covarianceFromInertia(tm.inertia);
    const Mat3 target =
        O * core::covarianceFromInertia(r->normalization.canonicalMoments.asDiagonal()) * O.transpose();
    const Vec3 a = (target.diagonal().array() / body.diagonal().array()).sqrt().matrix();
    core::TetMesh stretched = entry.tetMesh;
    for (Vec3& p : stretched.nodes)
      p = tm.centerOfMass + a.cwiseProduct(p - tm.centerOfMass);
    auto modes = volume::computeModes(stretched, db->parameters().entry.modal);
    if (!modes) {
      std::fprintf(stderr, "%s: %s\n", argv[i], modes.error().message.c_str());
      continue;
    }
    const double ratio = modes->eigenvalues[0] / entry.modes.eigenvalues[0];
    const double f1 = std::sqrt(r->physics->eigenvalues[0]) / (2 * M_PI);
    const double det = a.prod();
    std::string name = argv[i];
    name = name.substr(name.find_last_of('/') + 1);
    name = name.substr(0, name.find_last_of('.'));
    std::printf("%s,%s,%.6g,%.6g,%.6g,%.4f,%.4f,%.4f,%.4f\n", name.c_str(),
                r->answeredMatch().entry ? r->answeredMatch().entry->name.c_str() : "?", f1,
                f1 * std::sqrt(ratio), f1 * std::sqrt(ratio * std::pow(det, 2.0 / 3.0)), a.x(), a.y(), a.z(),
                det);
    std::fflush(stdout);
  }
}
