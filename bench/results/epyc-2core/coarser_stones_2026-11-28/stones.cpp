// Scratch: stone entries from other base spheres: tets and accuracy (build meshing vs fine), per index.
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/modal.h>
#include <shapedb/volume/tetrahedralize.h>

#include "family_shapes.h"
using namespace shapedb;
using core::Vec3;
core::TriangleMesh stone(core::TriangleMesh mesh, double a, double b, double amplitude,
                         std::mt19937_64& rng) {
  constexpr int kWaves = 6;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  std::array<Vec3, kWaves> directions;
  std::array<double, kWaves> weights{}, frequencies{}, phases{};
  double total = 0.0;
  for (int k = 0; k < kWaves; ++k) {
    directions[k] = Vec3(normal(rng), normal(rng), normal(rng)).normalized();
    frequencies[k] = 1.0 + 2.5 * unit(rng);
    phases[k] = 2 * std::numbers::pi * unit(rng);
    weights[k] = 0.2 + unit(rng);
    total += weights[k];
  }
  for (Vec3& p : mesh.vertices) {
    const Vec3 d = p.normalized();
    double r = 1.0;
    for (int k = 0; k < kWaves; ++k)
      r += amplitude * weights[k] / total * std::sin(frequencies[k] * d.dot(directions[k]) + phases[k]);
    p = (r * d).cwiseProduct(Vec3(1.0, a, b));
  }
  return mesh;
}
int main(int argc, char** argv) {
  const std::string base = argv[1];
  const int n = std::atoi(argv[2]);
  const std::string outDir = argc > 3 ? argv[3] : "";
  double worstAll = 0;
  std::vector<double> errs;
  std::vector<size_t> tetsAll;
  for (int i = 0; i < n; ++i) {
    const auto index = static_cast<std::uint32_t>(
        i * 87 / n + (std::getenv("OFFSET") ? std::atoi(std::getenv("OFFSET")) : 0));
    auto spec = volume::familySpec(volume::Family::kStone, index);
    std::mt19937_64 rng = volume::detail::entryStream(index, 0x5A17);
    core::TriangleMesh sphere = base == "ico2"   ? core::makeIcosphere(1.0, 2)
                                : base == "ico1" ? core::makeIcosphere(1.0, 1)
                                : base == "ico3"
                                    ? core::makeIcosphere(1.0, 3)
                                    : core::makeUvEllipsoid(Vec3::Ones(), std::atoi(base.c_str() + 2),
                                                            std::atoi(base.c_str() + 2) / 2);
    core::TriangleMesh s = stone(sphere, spec.params.x(), spec.params.y(), spec.params.z(), rng);
    if (!outDir.empty()) {
      char nm[256];
      std::snprintf(nm, sizeof nm, "%s/stone_%s_%02d.obj", outDir.c_str(), base.c_str(), i);
      (void)io::saveMesh(s, nm);
    }
    auto mp = core::computeMassProperties(s);
    for (auto& p : s.vertices)
      p = (p - mp->centerOfMass) / std::cbrt(mp->volume);
    volume::TetrahedralizeOptions build;
    build.maxRadiusEdgeRatio = 3;
    build.maxVolumeFraction = argc > 4 ? std::atof(argv[4]) : 0.01;
    volume::TetrahedralizeOptions fine;
    fine.maxRadiusEdgeRatio = 1.5;
    fine.maxVolumeFraction = 0.01 / 27;
    auto tb = volume::tetrahedralize(s, build);
    auto tf = volume::tetrahedralize(s, fine);
    if (!tb || !tf) {
      std::printf("%d: tetgen failed\n", i);
      continue;
    }
    volume::ModalOptions mo;
    mo.modes = 5;
    auto mb = volume::computeModes(*tb, mo), mf = volume::computeModes(*tf, mo);
    if (!mb || !mf) {
      std::printf("%d: modes failed\n", i);
      continue;
    }
    auto fb = mb->frequenciesHz(), ff = mf->frequenciesHz();
    double worst = 0;
    for (int k = 0; k < 5; ++k) {
      const double e = fb[k] / ff[k] - 1;
      worst = std::max(worst, e);
      errs.push_back(e);
    }
    worstAll = std::max(worstAll, worst);
    tetsAll.push_back(tb->tetCount());
    std::printf("stone-%05u %s: %zu triangles, %zu tets, worst %.2f %%\n", index, base.c_str(),
                s.triangles.size(), tb->tetCount(), 100 * worst);
  }
  std::sort(errs.begin(), errs.end());
  std::sort(tetsAll.begin(), tetsAll.end());
  std::printf("%s: median tets %zu, median error %.2f %%, worst %.2f %%\n", base.c_str(),
              tetsAll[tetsAll.size() / 2], 100 * errs[errs.size() / 2], 100 * worstAll);
}
