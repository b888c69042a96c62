#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/adapt.h>
#include <shapedb/core/primitives.h>
#include <shapedb/core/spatial.h>

#include "test_support.h"

namespace shapedb::core {
namespace {

TEST(Adapt, ScalesMassFrequenciesAndModesAndPlacesTheTets) {
  std::mt19937_64 rng(5);
  PhysicalData entry;
  entry.tetMesh = test::makeTetGrid(2, 2, 2, 0.1, rng);
  for (Vec3& x : entry.tetMesh.nodes)
    x = (x - Vec3::Constant(1.0)) / 2.0;  // unit volume, centred
  entry.massProperties = computeTetMassProperties(entry.tetMesh);
  const Eigen::Index n = 3 * static_cast<Eigen::Index>(entry.tetMesh.nodeCount());
  entry.modes.poissonRatio = 0.3;
  entry.modes.eigenvalues.resize(3);
  entry.modes.eigenvalues << 2.0, 5.0, 9.0;
  entry.modes.shapes = Eigen::MatrixXd::Random(n, 3);
  entry.collision.shapes.push_back(
      {CollisionShape::Type::kCapsule, Vec3(0.1, 0, 0), Mat3::Identity(), Vec3::Zero(), 0.2, 0.3});

  // The query: the same cube, scaled by 3 (L = 3), turned and moved.
  const double L = 3.0;
  Normalization q;
  q.scale = 1.0 / L;
  q.principalAxes = test::randomRotation(rng);
  q.meshFromCanonical.topLeftCorner<3, 3>() = L * q.principalAxes;
  q.meshFromCanonical.topRightCorner<3, 1>() = Vec3(4, 5, 6);
  MassProperties qm;
  qm.density = 1.0;
  qm.volume = L * L * L;
  qm.mass = qm.volume;
  qm.inertia = Mat3::Identity() * std::pow(L, 5) / 6.0;
  const Mat3 orientation = Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitY()).toRotationMatrix();

  Material steel = *materialPreset("Steel");
  auto a = adapt(entry, q, qm, orientation, steel, {2.0, 1e-6});
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_TRUE(a->warnings.empty());
  EXPECT_NEAR(a->massProperties.mass, 7850.0 * 27.0, 1e-6);
  EXPECT_NEAR(a->entryMassProperties.mass, 7850.0 * 27.0, 1e-6);
  EXPECT_LT((a->entryMassProperties.centerOfMass - Vec3(4, 5, 6)).norm(), 1e-9);
  const Eigen::VectorXd expected = entry.modes.frequenciesHz() * std::sqrt(200e9 / 7850.0) / L;
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(a->frequenciesHz()[i] / expected[i], 1.0, 1e-12);
  // Placement: node i sits at c + L R Oᵀ e.
  const Mat3 A = q.principalAxes * orientation.transpose();
  for (std::size_t i = 0; i < entry.tetMesh.nodeCount(); ++i)
    ASSERT_LT((a->tetMesh.nodes[i] - (Vec3(4, 5, 6) + L * A * entry.tetMesh.nodes[i])).norm(), 1e-12);
  // Tet mass properties of the placed mesh at steel's density equal the scaled entry's.
  const MassProperties placed = computeTetMassProperties(a->tetMesh, steel.density);
  EXPECT_NEAR(placed.mass / a->entryMassProperties.mass, 1.0, 1e-12);
  EXPECT_LT((placed.inertia - a->entryMassProperties.inertia).norm() / placed.inertia.norm(), 1e-12);
  // Mode shapes: rotated node by node, scaled by 1/sqrt(ρL³).
  const double s = 1.0 / std::sqrt(steel.density * L * L * L);
  for (Eigen::Index i = 0; i < n / 3; ++i)
    ASSERT_LT((a->modeShapes.block<3, 3>(3 * i, 0) - s * A * entry.modes.shapes.block<3, 3>(3 * i, 0)).norm(),
              1e-12);
  // Collision: centre placed, sizes scaled.
  const CollisionShape& c = a->collision.shapes[0];
  EXPECT_LT((c.center - (Vec3(4, 5, 6) + L * A * Vec3(0.1, 0, 0))).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(c.radius, 0.6);
  EXPECT_DOUBLE_EQ(c.halfLength, 0.9);

  Material rubber = *materialPreset("rubber");
  auto r = adapt(entry, q, qm, orientation, rubber, {});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->warnings.size(), 1u) << "rubber's Poisson ratio is not the database's";
  EXPECT_FALSE(materialPreset("unobtainium"));
  EXPECT_FALSE(adapt(entry, q, qm, orientation, Material{"bad", -1.0, 1.0, 0.3}, {}));
}

TEST(BlendSpectra, OneSampleOrAnExactMatchIsItsOwnSpectrum) {
  const Eigen::VectorXd a = (Eigen::VectorXd(3) << 2.0, 5.0, 9.0).finished();
  const Eigen::VectorXd b = (Eigen::VectorXd(3) << 4.0, 6.0, 7.0).finished();
  std::vector<double> weights;
  const std::vector<SpectrumSample> alone{{&a, 0.3}};
  EXPECT_EQ(blendSpectra(alone, &weights), a);
  EXPECT_EQ(weights, std::vector<double>{1.0});
  // At distance 0 the query is the entry's own shape: the others do not count, however near.
  const std::vector<SpectrumSample> exact{{&a, 0.0}, {&b, 1e-9}};
  EXPECT_EQ(blendSpectra(exact, &weights), a);
  EXPECT_EQ(weights, (std::vector<double>{1.0, 0.0}));
  // Two at distance 0 share it: the geometric mean.
  const std::vector<SpectrumSample> tied{{&a, 0.0}, {&b, 0.0}};
  const Eigen::VectorXd mean = blendSpectra(tied, &weights);
  for (Eigen::Index i = 0; i < 3; ++i)
    EXPECT_NEAR(mean[i], std::sqrt(a[i] * b[i]), 1e-12 * mean[i]);
  EXPECT_EQ(weights, (std::vector<double>{0.5, 0.5}));
}

TEST(BlendSpectra, WeighsByInverseDistanceWithinReachOfTheNearest) {
  const Eigen::VectorXd a = (Eigen::VectorXd(2) << 1.0, 4.0).finished();
  const Eigen::VectorXd b = (Eigen::VectorXd(2) << 8.0, 4.0).finished();
  const Eigen::VectorXd c = (Eigen::VectorXd(2) << 100.0, 100.0).finished();
  std::vector<double> weights;
  // b twice as far as a: weights 2/3 and 1/3, so the first mode is 1^(2/3) 8^(1/3) = 2. c lies beyond
  // kSpectrumReach times the nearest distance: another kind of shape, left out.
  const std::vector<SpectrumSample> samples{{&a, 0.1}, {&b, 0.2}, {&c, 0.2 * kSpectrumReach}};
  const Eigen::VectorXd blended = blendSpectra(samples, &weights);
  EXPECT_NEAR(blended[0], 2.0, 1e-12);
  EXPECT_NEAR(blended[1], 4.0, 1e-12);
  ASSERT_EQ(weights.size(), 3u);
  EXPECT_NEAR(weights[0], 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(weights[1], 1.0 / 3.0, 1e-15);
  EXPECT_EQ(weights[2], 0.0);
}

TEST(BlendSpectra, RandomSamplesBlendWithinTheirRangeAndScaleAsTheyDo) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int k = 1 + static_cast<int>(rng() % 6), m = 1 + static_cast<int>(rng() % 8);
    std::vector<Eigen::VectorXd> spectra(static_cast<std::size_t>(k));
    std::vector<SpectrumSample> samples;
    double distance = 0.01 + unit(rng);
    for (int j = 0; j < k; ++j) {
      // The first (the nearest) has m modes; the others m or fewer: a mode is blended over those that have
      // it.
      const int modes = j == 0 ? m : 1 + static_cast<int>(rng() % static_cast<unsigned>(m));
      spectra[static_cast<std::size_t>(j)] = (Eigen::VectorXd::Random(modes).array() + 1.5).exp().matrix();
      std::sort(spectra[static_cast<std::size_t>(j)].begin(), spectra[static_cast<std::size_t>(j)].end());
      samples.push_back({&spectra[static_cast<std::size_t>(j)], distance});
      distance *= 1.0 + 1.5 * unit(rng);  // ascending, some beyond reach
    }
    std::vector<double> weights;
    const Eigen::VectorXd blended = blendSpectra(samples, &weights);
    ASSERT_EQ(blended.size(), m);
    double total = 0.0;
    for (int j = 0; j < k; ++j) {
      const double w = weights[static_cast<std::size_t>(j)];
      const double d = samples[static_cast<std::size_t>(j)].distance;
      total += w;
      EXPECT_EQ(w > 0.0, d <= kSpectrumReach * samples[0].distance) << trial << " " << j;
      if (j > 0 && w > 0.0) {
        EXPECT_LE(w, weights[static_cast<std::size_t>(j) - 1]);  // the nearer weighs more
      }
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
    for (Eigen::Index i = 0; i < m; ++i) {
      // Between the least and the largest of the blended samples' values of that mode.
      double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
      for (int j = 0; j < k; ++j)
        if (weights[static_cast<std::size_t>(j)] > 0.0 && i < spectra[static_cast<std::size_t>(j)].size()) {
          lo = std::min(lo, spectra[static_cast<std::size_t>(j)][i]);
          hi = std::max(hi, spectra[static_cast<std::size_t>(j)][i]);
        }
      EXPECT_GE(blended[i], lo * (1.0 - 1e-12)) << trial;
      EXPECT_LE(blended[i], hi * (1.0 + 1e-12)) << trial;
    }
    // A geometric mean: every spectrum scaled by s scales the blend by s; every distance scaled by t
    // changes nothing.
    const double s = 0.1 + 10.0 * unit(rng), t = 0.1 + 10.0 * unit(rng);
    std::vector<Eigen::VectorXd> scaled = spectra;
    std::vector<SpectrumSample> moved;
    for (int j = 0; j < k; ++j) {
      scaled[static_cast<std::size_t>(j)] *= s;
      moved.push_back(
          {&scaled[static_cast<std::size_t>(j)], t * samples[static_cast<std::size_t>(j)].distance});
    }
    const Eigen::VectorXd rescaled = blendSpectra(moved);
    for (Eigen::Index i = 0; i < m; ++i)
      EXPECT_NEAR(rescaled[i] / (s * blended[i]), 1.0, 1e-10) << trial;
  }
}

}  // namespace
}  // namespace shapedb::core
