#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <shapedb/core/index.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/orientation.h>
#include <shapedb/core/primitives.h>
#include <shapedb/volume/describe.h>

#include "support/synthetic.h"
#include "support/test_support.h"

namespace shapedb::volume {
namespace {

using core::Descriptor;
using core::DescriptorKind;
using core::DescriptorOptions;
using core::Sampling;
using core::TriangleMesh;
using core::Vec3;

Descriptor describeOrDie(const TriangleMesh& mesh, const DescriptorOptions& options) {
  Result<test::DescribedMesh> d = test::describeMesh(mesh, options);
  EXPECT_TRUE(d.ok()) << (d ? "" : d.error().message);
  return d ? d->descriptor : Descriptor{};
}

TEST(Describe, BoxWithFacesOnCellPlanesFillsExactlyItsCells) {
  // A 3 × 2 × 1 box on a 6-grid: side 3 units, cells of 0.5, faces at y = ±1 and z = ±0.5 lie on
  // cell planes; the box covers x cells 0–5, y 1–4, z 2–3, every one of them touching a face.
  const TriangleMesh box = core::makeBox(Vec3(3.0, 2.0, 1.0));
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const TriangleMesh mesh = trial == 0 ? box : core::transformed(box, test::randomSimilarity(rng));
    const Descriptor d =
        describeOrDie(mesh, test::descriptorOptions(DescriptorKind::kCentroidVoxel, Sampling::kArea, 6));
    std::vector<std::uint32_t> expected;
    for (int k = 2; k <= 3; ++k)
      for (int j = 1; j <= 4; ++j)
        for (int i = 0; i <= 5; ++i)
          expected.push_back(static_cast<std::uint32_t>(i + 6 * (j + 6 * k)));
    ASSERT_EQ(d.cells, expected) << "trial " << trial;

    // The weights are the area of the unit-volume box; the surface's centroid is the origin.
    const double unit = std::cbrt(6.0);
    double area = 0.0;
    Vec3 moment = Vec3::Zero();
    for (std::size_t c = 0; c < d.cells.size(); ++c) {
      area += d.weights[c];
      moment += d.weights[c] * d.canonicalCentroid(c);
      EXPECT_TRUE((d.centroids[c].array() >= 0.0).all() && (d.centroids[c].array() <= 1.0).all());
    }
    EXPECT_NEAR(area, 22.0 / (unit * unit), 1e-12);
    EXPECT_LT(moment.norm(), 1e-12);
  }
}

// The 24 proper rotations that permute and reverse axes.
std::vector<core::Mat3> signedPermutations() {
  std::vector<core::Mat3> out;
  std::array<int, 3> axes{0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      core::Mat3 r = core::Mat3::Zero();
      for (int a = 0; a < 3; ++a)
        r(a, axes[static_cast<std::size_t>(a)]) = (signs >> a & 1) ? -1.0 : 1.0;
      if (r.determinant() > 0.0) out.push_back(r);
    }
  } while (std::next_permutation(axes.begin(), axes.end()));
  return out;
}

// Reindexing the canonical grid (what describeCandidates does for such candidates) against describing
// the surface again in the rotated frame: boxes with faces on cell planes, random shapes.
TEST(Describe, ReorientedDescriptorEqualsDescribingInTheRotatedFrame) {
  const std::vector<core::Mat3> rotations = signedPermutations();
  ASSERT_EQ(rotations.size(), 24u);
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 12; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const TriangleMesh mesh = trial == 0   ? core::makeBox(Vec3(3.0, 2.0, 1.0))
                              : trial == 1 ? test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 3)
                                           : test::makeRandomShape(rng, 3);
    const int gridSize = trial == 0 ? 6 : 10;
    for (DescriptorKind kind : {DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel}) {
      Describer describer(test::descriptorOptions(kind, Sampling::kArea, gridSize));
      Result<test::DescribedMesh> described =
          test::describeMesh(mesh, test::descriptorOptions(kind, Sampling::kArea, gridSize));
      ASSERT_TRUE(described.ok());
      const core::Normalization& normalization = described->normalization;
      const Result<Descriptor> canonical = describer.describe(mesh, normalization);
      ASSERT_TRUE(canonical.ok());
      for (const core::Mat3& rotation : rotations) {
        const Result<Descriptor> direct = describer.describe(mesh, normalization, rotation);
        ASSERT_TRUE(direct.ok());
        const std::optional<Descriptor> moved = core::reorientDescriptor(*canonical, rotation);
        ASSERT_TRUE(moved.has_value());
        ASSERT_EQ(moved->cells, direct->cells) << rotation;
        EXPECT_EQ(moved->orientation, direct->orientation);
        for (std::size_t c = 0; c < direct->cells.size(); ++c) {
          EXPECT_LT((moved->centroids[c] - direct->centroids[c]).norm(), 1e-9);
          EXPECT_NEAR(moved->weights[c], direct->weights[c], 1e-9 * direct->weights[c]);
        }
        EXPECT_LT(core::descriptorDistance(*moved, *direct), 1e-9);
      }
    }
  }
  // A turn that is not a quarter turn cannot be reindexed.
  const core::Mat3 turn = Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_FALSE(core::reorientDescriptor(Descriptor{}, turn).has_value());
}

// A round shape's frame is free to turn about its axis: 24 turns, and 48 where the axis's sign is
// undetermined too, of which describeCandidates describes a quarter's worth from the surface and reindexes
// the rest. Every candidate against describing the surface in its frame.
TEST(Describe, EveryCandidateOfARoundShapeEqualsDescribingItInItsFrame) {
  std::mt19937_64 rng(21);
  struct Round {
    TriangleMesh mesh;
    std::size_t candidates;
  };
  const std::vector<Round> shapes = {
      {core::makeCylinder(0.5, 3.0, 40), 48},  // mirror-symmetric: its axis may be reversed
      {core::makeCone(1.0, 2.5, 40), 24},      // its axis points to its tip
  };
  for (const Round& round : shapes) {
    const TriangleMesh mesh = core::transformed(round.mesh, test::randomSimilarity(rng));
    for (DescriptorKind kind : {DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel}) {
      const DescriptorOptions options = test::descriptorOptions(kind, Sampling::kArea);
      Result<test::DescribedMesh> described = test::describeMesh(mesh, options);
      ASSERT_TRUE(described.ok());
      const core::Normalization& normalization = described->normalization;
      ASSERT_EQ(normalization.planeSymmetry, 0);
      Describer describer(options);
      const Result<std::vector<Descriptor>> candidates = describer.describeCandidates(mesh, normalization);
      ASSERT_TRUE(candidates.ok());
      ASSERT_EQ(candidates->size(), round.candidates);
      const std::vector<core::Mat3> rotations = core::orientationCandidates(normalization);
      for (std::size_t c = 0; c < candidates->size(); ++c) {
        SCOPED_TRACE("candidate " + std::to_string(c));
        const Descriptor& reused = (*candidates)[c];
        EXPECT_EQ(reused.orientation, rotations[c]);
        const Result<Descriptor> direct = describer.describe(mesh, normalization, rotations[c]);
        ASSERT_TRUE(direct.ok());
        ASSERT_EQ(reused.cells, direct->cells);
        for (std::size_t i = 0; i < direct->cells.size(); ++i) {
          EXPECT_LT((reused.centroids[i] - direct->centroids[i]).norm(), 1e-9);
          EXPECT_NEAR(reused.weights[i], direct->weights[i], 1e-9 * direct->weights[i]);
        }
      }
    }
  }
}

TEST(Describe, VertexSamplingBinsTheVerticesAsThePaperDoes) {
  const TriangleMesh mesh = test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 2);
  const Descriptor d =
      describeOrDie(mesh, test::descriptorOptions(DescriptorKind::kVoxel, Sampling::kVertices));
  double count = 0.0;
  for (double w : d.weights)
    count += w;
  EXPECT_EQ(count, static_cast<double>(mesh.vertices.size()));
  EXPECT_LE(d.cells.size(), mesh.vertices.size());
}

TEST(Describe, MomentDescriptorIsTheCanonicalMoments) {
  const TriangleMesh mesh = test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 2);
  Result<test::DescribedMesh> d =
      test::describeMesh(mesh, test::descriptorOptions(DescriptorKind::kMoment, Sampling::kArea));
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->descriptor.moments, d->normalization.canonicalMoments);
  EXPECT_TRUE(d->descriptor.cells.empty());
}

TEST(Describe, RejectsOptionsOutOfRange) {
  const TriangleMesh mesh = core::makeBox(Vec3(1, 2, 3));
  for (int grid : {0, 1, core::kMaxGridSize + 1}) {
    Result<test::DescribedMesh> d =
        test::describeMesh(mesh, test::descriptorOptions(DescriptorKind::kVoxel, Sampling::kArea, grid));
    ASSERT_FALSE(d.ok());
    EXPECT_EQ(d.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(d.error().message.find("grid size"), std::string::npos);
  }
}

TEST(Describe, RefusesMalformedMeshesInsteadOfReadingOutOfBounds) {
  TriangleMesh mesh = core::makeBox(Vec3(1, 2, 3));
  const core::Normalization n = *core::normalize(mesh, *core::computeMassProperties(mesh));
  TriangleMesh broken = mesh;
  broken.triangles[3][1] = 99;
  Result<Descriptor> d = describe(broken, n);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().code, ErrorCode::kIndexOutOfRange);
  EXPECT_NE(d.error().message.find("triangle 3 refers to vertex 99 of 8"), std::string::npos);
  broken = mesh;
  broken.vertices[2].y() = std::numeric_limits<double>::quiet_NaN();
  d = describe(broken, n);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().code, ErrorCode::kNonFinite);
}

// The must-show invariance: 1,000 random rigid transforms and scales, the same descriptor, and the
// shape finds itself first among others.
TEST(Describe, SameDescriptorAndSelfMatchUnderThousandRandomSimilarities) {
  const TriangleMesh shape = test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 3);
  std::mt19937_64 shapes(11);
  std::vector<TriangleMesh> others;
  for (int i = 0; i < 300; ++i)
    others.push_back(test::makeRandomShape(shapes, 2));

  for (Sampling sampling : {Sampling::kArea, Sampling::kVertices}) {
    for (DescriptorKind kind :
         {DescriptorKind::kMoment, DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel}) {
      SCOPED_TRACE(std::string(core::toString(kind)) + " / " + core::toString(sampling));
      const DescriptorOptions options = test::descriptorOptions(kind, sampling);
      const Descriptor reference = describeOrDie(shape, options);
      core::IndexBuilder builder(options);
      ASSERT_TRUE(builder.add(0, reference).ok());
      for (std::size_t i = 0; i < others.size(); ++i)
        ASSERT_TRUE(builder.add(static_cast<core::EntryId>(i + 1), describeOrDie(others[i], options)).ok());
      Result<core::Index> index = std::move(builder).build();
      ASSERT_TRUE(index.ok());

      std::mt19937_64 rng(2024);
      int differentCells = 0;
      double worstMoment = 0.0, worstCentroid = 0.0;
      for (int trial = 0; trial < 1000; ++trial) {
        const Descriptor d = describeOrDie(core::transformed(shape, test::randomSimilarity(rng)), options);
        worstMoment = std::max(
            worstMoment,
            ((d.moments - reference.moments).cwiseAbs().array() / reference.moments.array()).maxCoeff());
        if (d.cells != reference.cells) {
          ++differentCells;
        } else {
          for (std::size_t c = 0; c < d.cells.size(); ++c)
            worstCentroid =
                std::max(worstCentroid, (d.centroids[c] - reference.centroids[c]).cwiseAbs().maxCoeff());
        }
        Result<std::vector<core::Match>> top = index->search(d);
        ASSERT_TRUE(top.ok());
        ASSERT_EQ(top->size(), 1u);
        EXPECT_EQ(top->front().entry, 0u) << "trial " << trial << ": matched " << top->front().entry;
      }
      EXPECT_LT(worstMoment, 1e-9);
      EXPECT_EQ(differentCells, 0);
      EXPECT_LT(worstCentroid, 1e-6);
    }
  }
}

// The describer's shortcuts (one cell, one plane, triangles split into triangles, polygons peeled slab by
// slab) against the oracle that clips every triangle against every cell of its range on its own: random
// shapes under random similarities, fine and coarse tessellations, several grid sizes, every orientation
// candidate's frame (sign flips and turns).
TEST(Describe, AreaSamplingAgreesWithClippingEveryCellOnItsOwn) {
  std::mt19937_64 rng(77);
  std::vector<TriangleMesh> shapes = {
      test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 4),  // 5,120 small triangles
      test::makeLopsidedBlob(Vec3(1.0, 0.3, 0.2), 1),  // 80 large ones
      core::makeBox(Vec3(1.0, 0.5, 0.25)),             // faces on cell planes
      core::makeUvEllipsoid(Vec3(1.0, 1.0, 0.4), 40, 20)};
  for (int i = 0; i < 8; ++i)
    shapes.push_back(test::makeRandomShape(rng, 1 + i % 3));
  int compared = 0;
  for (int grid : {10, 7, 23}) {
    for (const TriangleMesh& shape : shapes) {
      const TriangleMesh mesh = core::transformed(shape, test::randomSimilarity(rng));
      const DescriptorOptions options =
          test::descriptorOptions(DescriptorKind::kCentroidVoxel, Sampling::kArea, grid);
      Result<core::MassProperties> mp = core::computeMassProperties(mesh);
      ASSERT_TRUE(mp.ok());
      Result<core::Normalization> n = core::normalize(mesh, *mp);
      ASSERT_TRUE(n.ok());
      Describer describer(options);
      for (const core::Mat3& rotation : core::orientationCandidates(*n)) {
        Result<Descriptor> fast = describer.describe(mesh, *n, rotation);
        Result<Descriptor> slow = describeReference(mesh, *n, options, rotation);
        ASSERT_TRUE(fast.ok() && slow.ok());
        ASSERT_EQ(fast->cells, slow->cells)
            << "grid " << grid << ", " << mesh.triangleCount() << " triangles";
        for (std::size_t c = 0; c < fast->cells.size(); ++c) {
          EXPECT_NEAR(fast->weights[c], slow->weights[c], 1e-12 * (1.0 + slow->weights[c]));
          EXPECT_LT((fast->centroids[c] - slow->centroids[c]).cwiseAbs().maxCoeff(), 1e-9);
        }
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 36);
}

// Large meshes are binned in chunks in parallel; the chunks depend on the triangle count only, so the
// descriptor is the same to the bit on one thread as on many.
TEST(Describe, ChunkedAreaSamplingIsTheSameOnOneThreadAndMany) {
  const TriangleMesh mesh =
      core::subdivideMidpoint(test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 4));  // 20,480
  const DescriptorOptions options = test::descriptorOptions(DescriptorKind::kCentroidVoxel, Sampling::kArea);
  const Descriptor many = describeOrDie(mesh, options);
  Descriptor one;
  {
    const tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = describeOrDie(mesh, options);
  }
  EXPECT_EQ(one.cells, many.cells);
  EXPECT_EQ(one.centroids, many.centroids);
  EXPECT_EQ(one.weights, many.weights);
}

// Area sampling sees the surface, not its tessellation; vertex sampling sees the vertices.
TEST(Describe, AreaSamplingIgnoresTessellationVertexSamplingDoesNot) {
  const TriangleMesh mesh = test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 3);     // 1,280 triangles
  const TriangleMesh finer = core::subdivideMidpoint(mesh);                     // the same surface, 5,120
  const TriangleMesh coarser = test::makeLopsidedBlob(Vec3(1.0, 0.7, 0.5), 2);  // 320, a coarser surface
  std::map<std::string, double> figures;
  for (Sampling sampling : {Sampling::kArea, Sampling::kVertices})
    for (DescriptorKind kind : {DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel}) {
      const DescriptorOptions options = test::descriptorOptions(kind, sampling);
      const Descriptor base = describeOrDie(mesh, options);
      const std::string key = std::string(core::toString(kind)) + "/" + core::toString(sampling);
      figures[key + " finer"] = core::descriptorDistance(base, describeOrDie(finer, options));
      figures[key + " coarser"] = core::descriptorDistance(base, describeOrDie(coarser, options));
    }
  for (const auto& [name, value] : figures) {
    std::cout << "  distance " << name << ": " << value << "\n";
    RecordProperty(name, std::to_string(value));
  }
  for (const char* kind : {"voxel", "centroid-voxel"}) {
    const std::string k = kind;
    EXPECT_LT(figures[k + "/area finer"], 1e-6);
    EXPECT_LT(figures[k + "/area coarser"], 0.1);
    EXPECT_GT(figures[k + "/vertices finer"], 10.0 * figures[k + "/area finer"] + 0.05);
    EXPECT_GT(figures[k + "/vertices coarser"], figures[k + "/area coarser"]);
  }
}

// Worst distances, over random similarities of `shape`, between its descriptor and that of the moved
// copy in the canonical frame alone, and at the best orientation candidate.
struct OrientationFigures {
  double canonicalOnly = 0.0, bestCandidate = 0.0;
  std::size_t candidates = 0;
  int planeSymmetry = -1;
};
OrientationFigures orientationFigures(const TriangleMesh& shape, core::AxisDegeneracy expected) {
  const DescriptorOptions options = test::descriptorOptions(DescriptorKind::kCentroidVoxel, Sampling::kArea);
  const Descriptor reference = describeOrDie(shape, options);
  OrientationFigures f;
  std::mt19937_64 rng(5);
  Describer describer(options);
  for (int trial = 0; trial < 30; ++trial) {
    const TriangleMesh mesh = core::transformed(shape, test::randomSimilarity(rng));
    Result<core::MassProperties> mp = core::computeMassProperties(mesh);
    EXPECT_TRUE(mp.ok());
    Result<core::Normalization> n = core::normalize(mesh, *mp);
    EXPECT_TRUE(n.ok());
    EXPECT_EQ(n->degeneracy, expected);
    Result<std::vector<Descriptor>> candidates = describer.describeCandidates(mesh, *n);
    EXPECT_TRUE(candidates.ok());
    double best = 1.0;
    for (const Descriptor& c : *candidates)
      best = std::min(best, core::descriptorDistance(reference, c));
    f.canonicalOnly = std::max(f.canonicalOnly, core::descriptorDistance(reference, candidates->front()));
    f.bestCandidate = std::max(f.bestCandidate, best);
    f.candidates = candidates->size();
    f.planeSymmetry = n->planeSymmetry;
  }
  std::cout << "  worst distance over 30 similarities: canonical frame only " << f.canonicalOnly
            << ", best of " << f.candidates << " candidates " << f.bestCandidate << "\n";
  return f;
}

// A square-section bar has two equal moments, so they leave its frame free to turn about x; the fourth
// harmonic of its section fixes y and z up to quarter turns.
TEST(Describe, SquareBarFrameIsFixedByItsHarmonic) {
  const OrientationFigures f =
      orientationFigures(core::makeBox(Vec3(3.0, 1.0, 1.0)), core::AxisDegeneracy::kYZ);
  EXPECT_EQ(f.planeSymmetry, 4);
  EXPECT_LE(f.candidates, 8u);
  EXPECT_LT(f.canonicalOnly, 1e-6);
  EXPECT_LT(f.bestCandidate, 1e-6);
}

// An octagonal prism: equal moments, no harmonic of order ≤ 6, so the candidates turn every 15°.
TEST(Describe, OrientationCandidatesRecoverAFrameTurnedInADegeneratePlane) {
  const OrientationFigures f = orientationFigures(core::makeCylinder(0.5, 3.0, 8), core::AxisDegeneracy::kYZ);
  EXPECT_EQ(f.planeSymmetry, 0);
  EXPECT_GE(f.candidates, 24u);
  EXPECT_LT(f.bestCandidate, 0.5 * f.canonicalOnly);
}

}  // namespace
}  // namespace shapedb::volume
