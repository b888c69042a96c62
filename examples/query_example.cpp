// Give a surface mesh physical data from a shapedb database, then shake it by its first mode.
//   query_example DB MESH [OUT.obj]
// Prints the best match, the mass and the first frequencies for steel, and writes the mesh displaced
// along its first mode of vibration (through the linking weights) to OUT.obj if given.

#include <cstdio>
#include <vector>

#include <shapedb/core/link.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s DB MESH [OUT.obj]\n", argv[0]);
    return 2;
  }
  auto db = shapedb::io::Database::open(argv[1]);
  if (!db) {
    std::fprintf(stderr, "%s\n", db.error().message.c_str());
    return 1;
  }
  auto mesh = shapedb::io::loadMesh(argv[2]);
  if (!mesh) {
    std::fprintf(stderr, "%s\n", mesh.error().message.c_str());
    return 1;
  }

  shapedb::io::QueryOptions options;  // centroid-voxel descriptor, best match, steel
  auto result = db->query(mesh->mesh, options);
  if (!result) {
    std::fprintf(stderr, "%s: %s\n", argv[2], result.error().message.c_str());
    return 1;
  }
  const shapedb::io::MatchReport& best = result->matches.front();
  const shapedb::core::AdaptedPhysics& physics = *result->physics;
  std::printf("best match: %s (distance %.4g, surface deviation %.2f%% of the size)\n",
              best.entry->name.c_str(), best.match.distance, 100.0 * best.fidelity->meanDeviation);
  std::printf("mass %.4g kg; first frequencies:", physics.massProperties.mass);
  for (Eigen::Index i = 0; i < std::min<Eigen::Index>(5, physics.eigenvalues.size()); ++i)
    std::printf(" %.1f", physics.frequenciesHz()[i]);
  std::printf(" Hz; query took %.0f us\n", result->times.total);

  if (argc > 3) {
    // u = φ₀ q: the first mode, scaled so that its largest displacement is 5 % of the object's size.
    const Eigen::VectorXd mode = physics.modeShapes.col(0);
    const double size = std::cbrt(physics.massProperties.volume);
    const Eigen::VectorXd u = mode * (0.05 * size / mode.cwiseAbs().maxCoeff());
    shapedb::core::TriangleMesh shaken = mesh->mesh;
    shapedb::core::deformSurface(result->link, physics.tetMesh, u, mesh->mesh.vertices, shaken.vertices);
    if (auto saved = shapedb::io::saveMesh(shaken, argv[3]); !saved) {
      std::fprintf(stderr, "%s\n", saved.error().message.c_str());
      return 1;
    }
    std::printf("wrote %s\n", argv[3]);
  }
  return 0;
}
