#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fcntl.h>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <random>
#include <sys/file.h>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tbb/task_arena.h>

#include <shapedb/core/error_model.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/database.h>
#include <shapedb/io/store.h>
#include <shapedb/volume/correction.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/modal.h>

#include "build_session.h"
#include "support/test_support.h"

namespace shapedb::io {
namespace {

using core::DescriptorKind;

BuildOptions smallBuild(std::size_t entries, std::vector<volume::Family> families, int modes = 6) {
  BuildOptions options;
  options.parameters.entries = entries;
  options.parameters.families = std::move(families);
  options.parameters.entry.modal.modes = modes;
  options.threads = 2;
  options.batchSize = 4;
  return options;
}

/// Entries of each family in the suite's database: one (sixteen families; the non-convex ones cost
/// seconds an entry under the sanitizers, and the database is most of this suite's time there).
constexpr std::size_t kPerFamily = 1;

/// The suite's database, built once per test binary and shared by the suite's ctest processes (each
/// test runs in a process of its own, and the build is most of their time under the sanitizers): beside
/// the binary, named after its size and modification time, built under a file lock by the first process
/// that wants it; databases of earlier binaries are removed then.
Result<std::filesystem::path> suiteDatabase() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  struct stat st {};
  if (ec || ::stat(exe.c_str(), &st) != 0) return Error{ErrorCode::kIo, "cannot find the test binary"};
  const std::string name = "small-" + std::to_string(st.st_size) + "-" + std::to_string(st.st_mtim.tv_sec) +
                           "." + std::to_string(st.st_mtim.tv_nsec) + ".db";
  const std::filesystem::path dir = exe.parent_path() / "test-cache";
  std::filesystem::create_directories(dir, ec);
  const int lock = ::open((dir / "lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock < 0) return Error{ErrorCode::kIo, (dir / "lock").string() + ": cannot open"};
  const std::unique_ptr<int, void (*)(int*)> unlock(new int(lock), [](int* fd) {
    ::close(*fd);  // releases the lock
    delete fd;
  });
  if (::flock(lock, LOCK_EX) != 0) return Error{ErrorCode::kIo, (dir / "lock").string() + ": cannot lock"};
  const std::filesystem::path path = dir / name;
  if (std::filesystem::exists(path)) return path;
  for (const auto& old : std::filesystem::directory_iterator(dir))
    if (old.path().filename() != "lock") std::filesystem::remove(old.path(), ec);
  const std::filesystem::path building = dir / (name + ".building");
  const auto families = volume::generatedFamilies();
  auto report =
      buildDatabase(building, smallBuild(kPerFamily * families.size(), {families.begin(), families.end()}));
  if (!report) return report.error();
  if (report->built != kPerFamily * families.size() || report->failed != 0)
    return Error{ErrorCode::kInvalidArgument, std::to_string(report->built) + " entries built, " +
                                                  std::to_string(report->failed) + " failed; expected " +
                                                  std::to_string(kPerFamily * families.size()) + " and 0"};
  std::filesystem::rename(building, path, ec);
  if (ec) return Error{ErrorCode::kIo, path.string() + ": " + ec.message()};
  return path;
}

/// The shape an entry of the suite's database was built from: its family, and its index from its name
/// ("box-00003").
volume::ShapeSpec entrySpec(const EntryRecord& e) {
  return volume::familySpec(e.family,
                            static_cast<std::uint32_t>(std::stoul(e.name.substr(e.name.find('-') + 1))));
}

// Entry e's own surface stretched by `stretch`: a query that its entry's tets are morphed onto.
core::TriangleMesh stretchedSurface(const Database& db, const EntryRecord& e, const core::Mat3& stretch) {
  core::TriangleMesh surface = *volume::makeFamilyShape(entrySpec(e), db.parameters().resolution);
  for (core::Vec3& v : surface.vertices)
    v = stretch * v;
  return surface;
}

// A corrected query that chooses among three candidates' morphs, without fidelity reports.
QueryOptions correctedAmongThree() {
  QueryOptions options;
  options.fidelity = false;
  options.correct = true;
  options.correctionCandidates = 3;
  return options;
}

/// Every entry's own surface, each under a random similarity (scale 0.5 to 2), in entry order.
std::vector<core::TriangleMesh> ownSurfacesUnderSimilarities(const Database& db, std::mt19937_64& rng) {
  std::vector<core::TriangleMesh> surfaces;
  for (const EntryRecord& e : db.entries())
    surfaces.push_back(core::transformed(*volume::makeFamilyShape(entrySpec(e), db.parameters().resolution),
                                         test::randomSimilarity(rng, 3.0, 0.5, 2.0)));
  return surfaces;
}

/// Whether a shape has a continuous symmetry that its normalization leaves open (two equal principal
/// moments and no angular harmonic of order 2 to 6 about the third axis: a ring, a cup, a tube). A query
/// finds it by the turns about that axis that it samples, so the match's frame is the query's only to
/// within half a turn step, and its descriptor distance, surface deviation and placed tets are close,
/// not exact.
bool turnsSampled(const core::TriangleMesh& surface) {
  const auto frame = core::normalize(surface, *core::computeMassProperties(surface));
  return frame->isDegenerate() && frame->planeSymmetry == 0;
}

/// `match`'s entry morphed on its own onto `query`, carried into the entry's canonical frame as the
/// query `r` placed it: what Database::query's correction does for one of its entries.
Result<volume::MorphedEntry> morphOntoQuery(const Database& db, const QueryResult& r,
                                            const core::TriangleMesh& query, const core::Match& match,
                                            const volume::CorrectionOptions& options) {
  const core::Placement placement = core::placementOf(r.normalization, match.orientation);
  core::TriangleMesh target = query;
  for (core::Vec3& v : target.vertices)
    v = placement.toEntry(v);
  auto entry = db.physics(match.entry);
  EXPECT_TRUE(entry.ok()) << "entry " << match.entry << ": " << (entry ? "" : entry.error().message);
  if (!entry) return entry.error();
  return volume::morphEntry(**entry, target, options);
}

/// One database for the suite: kPerFamily entries of each generated family. A build that fails fails every
/// test (an assertion in SetUpTestSuite would make GoogleTest skip them, and ctest report them as skipped).
class SmallDatabase : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sDir = new test::ScratchDir("database");
    auto path = suiteDatabase();
    if (path)
      sPath = *path;
    else
      sBuildError = path.error().message;
  }
  void SetUp() override { ASSERT_TRUE(sBuildError.empty()) << "the suite's database: " << sBuildError; }
  static void TearDownTestSuite() {
    delete sDir;
    sDir = nullptr;
  }
  static test::ScratchDir* sDir;
  static std::filesystem::path sPath;
  static std::string sBuildError;
};
std::string SmallDatabase::sBuildError;
test::ScratchDir* SmallDatabase::sDir = nullptr;
std::filesystem::path SmallDatabase::sPath;

TEST_F(SmallDatabase, EveryEntryQueriedWithItsOwnSurfaceUnderARigidTransformIsTopOne) {
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  ASSERT_EQ(db->entries().size(), kPerFamily * volume::generatedFamilies().size());
  std::mt19937_64 rng(2024);
  for (const EntryRecord& e : db->entries()) {
    const volume::ShapeSpec spec = entrySpec(e);
    ASSERT_EQ(spec.name(), e.name);
    auto surface = volume::makeFamilyShape(spec, db->parameters().resolution);
    ASSERT_TRUE(surface.ok());
    for (DescriptorKind kind :
         {DescriptorKind::kMoment, DescriptorKind::kVoxel, DescriptorKind::kCentroidVoxel}) {
      // A rigid transform: rotation and translation, scale 1 (the descriptors do not see scale anyway).
      const core::TriangleMesh moved =
          core::transformed(*surface, test::randomSimilarity(rng, 5.0, 1.0, 1.0));
      auto matches = db->match(moved, kind, {.k = 3});
      ASSERT_TRUE(matches.ok()) << matches.error().message;
      EXPECT_LT(matches->front().distance, turnsSampled(*surface) ? 1e-2 : 1e-6)
          << e.name << " " << core::toString(kind);
      if (kind == DescriptorKind::kVoxel && matches->front().entry != e.id) {
        // Binary occupancy cannot tell a short capsule from the cylinder of the same proportions on a 10³
        // grid: they fill the same cells. Then the entry must tie for first, at distance 0.
        const auto self = std::find_if(matches->begin(), matches->end(),
                                       [&](const core::Match& m) { return m.entry == e.id; });
        ASSERT_NE(self, matches->end()) << e.name;
        EXPECT_EQ(self->distance, matches->front().distance) << e.name;
        std::printf("voxel tie: %s and entry %u at distance %g\n", e.name.c_str(), matches->front().entry,
                    matches->front().distance);
        continue;
      }
      EXPECT_EQ(matches->front().entry, e.id)
          << e.name << " by " << core::toString(kind) << ": got entry " << matches->front().entry << " at "
          << matches->front().distance;
    }
  }
}

TEST_F(SmallDatabase, PhysicsReadBackMatchesAFreshComputation) {
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok());
  const EntryRecord& e = db->entries()[4];
  auto physics = db->physics(e.id);
  ASSERT_TRUE(physics.ok()) << physics.error().message;
  auto surface = volume::makeFamilyShape(entrySpec(e), db->parameters().resolution);
  ASSERT_TRUE(surface.ok());
  auto fresh = volume::computeEntry(*surface, db->parameters().entry);
  ASSERT_TRUE(fresh.ok());
  const core::PhysicalData& p = **physics;
  ASSERT_EQ(p.tetMesh.tets, fresh->physics.tetMesh.tets);
  ASSERT_EQ(p.tetMesh.nodes, fresh->physics.tetMesh.nodes);
  EXPECT_NEAR(p.massProperties.volume, 1.0, 1e-9);
  ASSERT_EQ(p.modes.modeCount(), 6u);
  EXPECT_EQ(p.modes.eigenvalues, fresh->physics.modes.eigenvalues);
  // Shapes are stored as 16-bit integers per mode: within 2⁻¹⁵ of the largest component.
  for (Eigen::Index i = 0; i < 6; ++i) {
    const double largest = fresh->physics.modes.shapes.col(i).cwiseAbs().maxCoeff();
    EXPECT_LT((p.modes.shapes.col(i) - fresh->physics.modes.shapes.col(i)).cwiseAbs().maxCoeff(),
              largest / 32767.0);
  }
  // Still M-orthonormal to ~1e-4 after that rounding: the stored corner values, completed at the mid-edge
  // nodes of the (default) quadratic tets by a fresh solve, with the quadratic mass.
  ASSERT_EQ(db->parameters().entry.modal.order, volume::ElementOrder::kQuadratic);
  const volume::QuadraticTetMesh quadratic = volume::makeQuadratic(p.tetMesh);
  auto all = volume::computeModes(quadratic, db->parameters().entry.modal);
  ASSERT_TRUE(all.ok()) << all.error().message;
  Eigen::MatrixXd shapes = all->shapes;
  shapes.topRows(p.modes.shapes.rows()) = p.modes.shapes;
  const volume::FemMatrices fem = volume::assembleFem(quadratic, core::unitMaterial());
  const Eigen::MatrixXd gram = shapes.transpose() * fem.mass * shapes;
  EXPECT_LT((gram - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(p.collision.shapes.size(), fresh->physics.collision.shapes.size());
  EXPECT_EQ(p.sound.frequenciesHz, fresh->physics.sound.frequenciesHz);
  // The second read comes from the cache.
  ASSERT_TRUE(db->physics(e.id).ok());
  EXPECT_EQ(db->cacheStats()[0], 1u);
}

TEST_F(SmallDatabase, EveryEntrysEigenvaluesReadAloneAreThoseOfItsData) {
  auto store = Store::open(sPath);
  ASSERT_TRUE(store.ok()) << store.error().message;
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  for (const EntryRecord& e : db->entries()) {
    auto eigenvalues = store->eigenvalues(e.id);
    ASSERT_TRUE(eigenvalues.ok()) << e.name << ": " << eigenvalues.error().message;
    auto physics = store->physics(e.id);
    ASSERT_TRUE(physics.ok()) << e.name;
    EXPECT_EQ(*eigenvalues, physics->modes.eigenvalues) << e.name;
  }
}

TEST_F(SmallDatabase, TheNearestTiersEigenvaluesBlendTheNearestMatchesSpectra) {
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  std::mt19937_64 rng(314);
  std::uniform_real_distribution<double> stretch(0.8, 1.25);
  std::size_t blendedQueries = 0;
  for (std::size_t i = 0; i < db->entries().size(); ++i) {
    // An entry's shape stretched along its axes and moved: no entry is it, several are near it.
    const EntryRecord& e = db->entries()[i];
    auto surface = volume::makeFamilyShape(entrySpec(e), db->parameters().resolution);
    ASSERT_TRUE(surface.ok());
    core::TriangleMesh query = *surface;
    const core::Vec3 a(stretch(rng), stretch(rng), stretch(rng));
    for (core::Vec3& v : query.vertices)
      v = a.cwiseProduct(v);
    query = core::transformed(query, test::randomSimilarity(rng, 3.0, 0.2, 5.0));
    QueryOptions options;
    options.fidelity = false;
    options.neighbours = 3;
    auto r = db->query(query, options);
    ASSERT_TRUE(r.ok()) << e.name << ": " << r.error().message;
    options.neighbours = 1;
    auto nearest = db->query(query, options);
    ASSERT_TRUE(nearest.ok()) << e.name << ": " << nearest.error().message;
    ASSERT_EQ(r->matches.size(), 3u) << "the search finds as many matches as are blended";
    ASSERT_EQ(nearest->matches.size(), 1u);
    EXPECT_EQ(nearest->spectrumWeights, std::vector<double>{1.0});
    ASSERT_EQ(r->matches[0].match.entry, nearest->matches[0].match.entry);
    // The oracle: the matches' stored spectra, blended, in place of the nearest's own.
    std::vector<std::shared_ptr<const core::PhysicalData>> data;
    std::vector<core::SpectrumSample> samples;
    for (const MatchReport& m : r->matches) {
      auto p = db->physics(m.match.entry);
      ASSERT_TRUE(p.ok());
      data.push_back(*p);
      samples.push_back({&data.back()->modes.eigenvalues, m.match.distance});
    }
    std::vector<double> weights;
    const Eigen::VectorXd blended = core::blendSpectra(samples, &weights);
    EXPECT_EQ(r->spectrumWeights, weights) << e.name;
    const Eigen::VectorXd& own = data.front()->modes.eigenvalues;
    ASSERT_EQ(r->physics->eigenvalues.size(), own.size());
    for (Eigen::Index m = 0; m < own.size(); ++m)
      EXPECT_NEAR(r->physics->eigenvalues[m] / nearest->physics->eigenvalues[m], blended[m] / own[m], 1e-12)
          << e.name << " mode " << m;
    // Only the eigenvalues: the shapes, the tets and the mass are the nearest entry's.
    EXPECT_EQ(r->physics->modeShapes, nearest->physics->modeShapes) << e.name;
    EXPECT_EQ(r->physics->tetMesh.nodes, nearest->physics->tetMesh.nodes) << e.name;
    EXPECT_EQ(r->physics->massProperties.mass, nearest->physics->massProperties.mass) << e.name;
    if (weights[1] > 0.0) ++blendedQueries;
  }
  // Some were blended (the others' second match, of another family here, lay beyond reach).
  std::printf("%zu of %zu queries blended\n", blendedQueries, db->entries().size());
  EXPECT_GT(blendedQueries, 0u);

  // The fidelity report covers the match asked for, not the neighbours blended beside it.
  QueryOptions reported;
  auto withFidelity = db->query(core::makeBox({1.0, 2.0, 3.0}), reported);
  ASSERT_TRUE(withFidelity.ok()) << withFidelity.error().message;
  ASSERT_EQ(withFidelity->matches.size(), 3u);
  EXPECT_TRUE(withFidelity->matches[0].fidelity.has_value());
  EXPECT_FALSE(withFidelity->matches[1].fidelity.has_value());
  EXPECT_FALSE(withFidelity->matches[2].fidelity.has_value());
  EXPECT_TRUE(withFidelity->predictedFrequencyError.has_value());

  QueryOptions bad;
  bad.neighbours = 0;
  auto refused = db->query(core::makeBox({1.0, 2.0, 3.0}), bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("neighbours"), std::string::npos) << refused.error().message;
}

TEST_F(SmallDatabase, AnEntryUnderASimilarityComesBackAsItselfAdaptedToTheQuerysSizeAndMaterial) {
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  std::mt19937_64 rng(77);
  const core::Material glass = *core::materialPreset("glass");
  for (std::size_t i = 0; i < db->entries().size(); i += kPerFamily) {  // one entry of each family
    const EntryRecord& e = db->entries()[i];
    const volume::ShapeSpec spec = entrySpec(e);
    auto surface = volume::makeFamilyShape(spec, db->parameters().resolution);
    ASSERT_TRUE(surface.ok());
    const core::TriangleMesh query =
        core::transformed(*surface, test::randomSimilarity(rng, 10.0, 0.05, 20.0));
    QueryOptions options;
    options.material = glass;
    options.search.k = 2;
    auto r = db->query(query, options);
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->matches.size(), 3u);  // k = 2, and as many as the answer's spectrum may be blended from
    EXPECT_EQ(r->matches[0].match.entry, e.id) << e.name;
    ASSERT_TRUE(r->matches[0].fidelity && r->matches[1].fidelity);
    const core::Fidelity& f = *r->matches[0].fidelity;
    // The answer's predicted error: the shipped model on the best match's evidence.
    ASSERT_TRUE(r->predictedFrequencyError) << e.name;
    core::ErrorEvidence evidence{
        f.meanDeviation,
        f.maxDeviation,
        f.maxMomentError,
        f.descriptorDistance,
        static_cast<double>(r->link.outsideCount) / static_cast<double>(query.vertexCount()),
        std::nullopt,
        std::nullopt,
        std::nullopt};
    EXPECT_DOUBLE_EQ(*r->predictedFrequencyError, core::predictFrequencyError(evidence)) << e.name;
    const bool sampled = turnsSampled(*surface);
    EXPECT_LT(f.descriptorDistance, sampled ? 1e-2 : 1e-6) << e.name;
    EXPECT_LT(f.maxMomentError, 1e-6) << e.name;
    EXPECT_LT(f.maxDeviation, sampled ? 1e-2 : 1e-6)
        << e.name << ": the placed tets' boundary is the query's surface";
    EXPECT_GT(r->matches[1].fidelity->meanDeviation, f.meanDeviation) << e.name;
    // Every match asked for has its own estimate, from its fidelity report: the worse match is predicted
    // worse. The third, found for the answer's spectrum, has neither.
    for (std::size_t asked = 0; asked < 2; ++asked) {
      const MatchReport& m = r->matches[asked];
      ASSERT_TRUE(m.predictedFrequencyError) << e.name;
      EXPECT_DOUBLE_EQ(*m.predictedFrequencyError,
                       core::predictFrequencyError(core::evidenceOf(*m.fidelity)));
    }
    EXPECT_FALSE(r->matches[2].fidelity.has_value()) << e.name;
    EXPECT_GT(*r->matches[1].predictedFrequencyError, *r->matches[0].predictedFrequencyError) << e.name;

    // Scaling laws against the query's own size L and the material.
    ASSERT_TRUE(r->physics.has_value());
    const core::AdaptedPhysics& p = *r->physics;
    const double L = std::cbrt(r->massProperties.volume);
    EXPECT_NEAR(p.massProperties.mass / (glass.density * r->massProperties.volume), 1.0, 1e-12);
    EXPECT_NEAR(p.entryMassProperties.mass / p.massProperties.mass, 1.0, 1e-6) << e.name;
    const Eigen::VectorXd expected =
        r->entryPhysics->modes.frequenciesHz() * std::sqrt(glass.youngsModulus / glass.density) / L;
    ASSERT_EQ(p.frequenciesHz().size(), expected.size());
    EXPECT_EQ(p.stretch, core::Vec3::Ones());  // the paper's uniform scaling, by default
    // Its own shape answers alone: the other matches lie far beyond kSpectrumReach times its distance.
    ASSERT_EQ(r->spectrumWeights.size(), 3u);
    EXPECT_EQ(r->spectrumWeights[0], 1.0) << e.name;
    for (Eigen::Index m = 0; m < expected.size(); ++m)
      EXPECT_NEAR(p.frequenciesHz()[m] / expected[m], 1.0, 1e-12);
    if (sampled) continue;  // the checks below need the query's own frame

    // The entry has the query's shape already: the geometry correction moves nothing (its boundary is the
    // query's surface), and the modes computed again on the unmoved tets are the entry's, for glass's own
    // Poisson ratio (0.22; the database's is 0.3): no warning about it.
    QueryOptions corrected = options;
    corrected.correct = true;
    corrected.fidelity = false;
    auto c = db->query(query, corrected);
    ASSERT_TRUE(c.ok() && c->physics && c->correction) << e.name;
    EXPECT_FALSE(c->predictedFrequencyError) << "no fidelity report, no evidence";
    EXPECT_TRUE(c->physics->warnings.empty()) << e.name << ": " << c->physics->warnings.front();
    EXPECT_LT(c->correction->morph.maxBoundaryMove, 1e-9) << e.name;
    EXPECT_LT(c->correction->morph.meanTargetDistance, 1e-9) << e.name;
    volume::ModalOptions glassModal = db->parameters().entry.modal;
    glassModal.material = glass;
    auto glassModes = volume::computeModes(p.tetMesh, glassModal);
    ASSERT_TRUE(glassModes.ok()) << e.name << ": " << glassModes.error().message;
    ASSERT_EQ(c->physics->frequenciesHz().size(), expected.size());
    for (Eigen::Index m = 0; m < expected.size(); ++m)
      EXPECT_NEAR(c->physics->frequenciesHz()[m] / glassModes->frequenciesHz()[m], 1.0, 1e-7)
          << e.name << " mode " << m;
    // Independently of the scaling code: the modes computed afresh on the adapted tets, in the query's
    // frame, units and material, are the adapted ones (frequencies to round-off; shapes to the 16 bits
    // they are stored in, up to sign, where a frequency is apart from its neighbours).
    volume::ModalOptions inQuery = db->parameters().entry.modal;
    inQuery.material = glass;
    inQuery.material.poissonRatio = 0.3;
    auto direct = volume::computeModes(p.tetMesh, inQuery);
    ASSERT_TRUE(direct.ok()) << e.name << ": " << direct.error().message;
    const Eigen::Index modes = p.modeShapes.cols();
    for (Eigen::Index m = 0; m < modes; ++m) {
      EXPECT_NEAR(direct->eigenvalues[m] / p.eigenvalues[m], 1.0, 1e-9) << e.name << " mode " << m;
      const bool isolated = (m == 0 || p.eigenvalues[m] > 1.01 * p.eigenvalues[m - 1]) &&
                            (m + 1 == modes || p.eigenvalues[m + 1] > 1.01 * p.eigenvalues[m]);
      if (!isolated) continue;
      const Eigen::VectorXd a = direct->shapes.col(m), b = p.modeShapes.col(m);
      const double sign = a.dot(b) < 0.0 ? -1.0 : 1.0;
      EXPECT_LT((a - sign * b).cwiseAbs().maxCoeff(), 1e-3 * a.cwiseAbs().maxCoeff())
          << e.name << " mode " << m;
    }

    // Linking: every vertex of the query lies on the placed tets' boundary.
    ASSERT_EQ(r->link.locations.size(), query.vertexCount());
    for (std::size_t v = 0; v < query.vertexCount(); ++v) {
      const core::TetLocation& l = r->link.locations[v];
      ASSERT_NEAR(l.weights[0] + l.weights[1] + l.weights[2] + l.weights[3], 1.0, 1e-12);
      core::Vec3 x = core::Vec3::Zero();
      for (int k = 0; k < 4; ++k)
        x += l.weights[k] * p.tetMesh.nodes[p.tetMesh.tets[l.tet][k]];
      ASSERT_LT((x - query.vertices[v]).norm(), 1e-9 * L) << e.name << " vertex " << v;
    }
    EXPECT_LT(r->link.maxOutsideDistance, 1e-9 * L);
  }
}

// A query that no entry's tets can be morphed onto (a needle, 120 : 1 : 1, far beyond every entry's
// proportions): the correction is refused, and the answer is the uncorrected one, with the reason.
TEST_F(SmallDatabase, ACorrectionThatWouldInvertATetKeepsTheEntrysDataAndSaysWhy) {
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  const core::TriangleMesh needle = core::makeBox({0.6, 0.005, 0.005});
  QueryOptions options;
  options.fidelity = false;
  auto plain = db->query(needle, options);
  ASSERT_TRUE(plain.ok() && plain->physics) << (plain ? "" : plain.error().message);
  options.correct = true;
  auto r = db->query(needle, options);
  ASSERT_TRUE(r.ok() && r->physics) << (r ? "" : r.error().message);
  EXPECT_FALSE(r->correction.has_value()) << db->entry(plain->matches[0].match.entry)->name;
  ASSERT_FALSE(r->physics->warnings.empty());
  EXPECT_NE(r->physics->warnings.back().find("geometry correction not applied"), std::string::npos)
      << r->physics->warnings.back();
  EXPECT_NE(r->physics->warnings.back().find("quality"), std::string::npos) << r->physics->warnings.back();
  EXPECT_EQ(r->physics->eigenvalues, plain->physics->eigenvalues);
  EXPECT_EQ(r->physics->tetMesh.nodes, plain->physics->tetMesh.nodes);
}

TEST_F(SmallDatabase, ConcurrentQueriesAgreeWithSerialOnes) {
  Database::OpenOptions small;
  small.cacheEntries = 4;
  auto db = Database::open(sPath, small);
  ASSERT_TRUE(db.ok());
  std::mt19937_64 rng(5);
  const std::vector<core::TriangleMesh> queries = ownSurfacesUnderSimilarities(*db, rng);
  std::vector<core::EntryId> serial;
  std::vector<double> serialHz;
  for (const auto& q : queries) {
    auto r = db->query(q);
    ASSERT_TRUE(r.ok());
    serial.push_back(r->matches[0].match.entry);
    serialHz.push_back(r->physics->frequenciesHz()[0]);
  }
  // Four threads, each querying every mesh in its own order, through a cache smaller than the set.
  std::vector<std::thread> threads;
  std::atomic<int> mismatches{0};
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (std::size_t n = 0; n < 3 * queries.size(); ++n) {
        const std::size_t i = (n * (2 * t + 1) + static_cast<std::size_t>(t)) % queries.size();
        auto r = db->query(queries[i]);
        if (!r.ok() || r->matches[0].match.entry != serial[i] ||
            r->physics->frequenciesHz()[0] != serialHz[i])
          ++mismatches;
      }
    });
  for (auto& t : threads)
    t.join();
  EXPECT_EQ(mismatches.load(), 0);
}

// The correction's choice among candidates against its oracle: each of the first three matches' entries
// morphed onto the query on its own (volume::morphEntry); the answer must carry the one nearest the
// query's surface (the first of equals), with the modes computed on exactly that morph. Queries: entries'
// own surfaces stretched out of their proportions, so that the candidates' morphs differ.
TEST_F(SmallDatabase, TheCorrectionAnswersWithTheCandidateWhoseMorphReachesTheQueryBest) {
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  const core::Mat3 stretch = core::Vec3(1.3, 0.9, 0.85).asDiagonal();
  std::size_t checked = 0;
  for (std::size_t n = 0; n < db->entries().size(); n += 8) {
    const EntryRecord& e = db->entries()[n];
    const core::TriangleMesh query = stretchedSurface(*db, e, stretch);
    QueryOptions options = correctedAmongThree();
    options.correctionFallback = false;  // the candidates alone: the fallback has its own test
    auto r = db->query(query, options);
    ASSERT_TRUE(r.ok() && r->physics) << e.name << ": " << (r ? "" : r.error().message);
    ASSERT_GE(r->matches.size(), 3u) << e.name;
    if (!r->correction) continue;  // no candidate could be morphed: the other test's case
    ++checked;

    std::optional<volume::MorphedEntry> best;
    std::size_t bestIndex = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      auto morphed = morphOntoQuery(*db, *r, query, r->matches[i].match, options.correction);
      if (morphed &&
          (!best || morphed->report.morph.meanTargetDistance < best->report.morph.meanTargetDistance)) {
        best = std::move(morphed).value();
        bestIndex = i;
      }
    }
    ASSERT_TRUE(best.has_value()) << e.name;
    EXPECT_EQ(r->answered, bestIndex) << e.name;
    EXPECT_EQ(r->answeredMatch().match.entry, r->matches[bestIndex].match.entry);
    EXPECT_EQ(r->correction->morphs, 3) << e.name;
    EXPECT_EQ(r->correction->morph.meanTargetDistance, best->report.morph.meanTargetDistance) << e.name;
    EXPECT_EQ(r->entryPhysics->tetMesh.nodes,
              (*db->physics(r->matches[bestIndex].match.entry))->tetMesh.nodes)
        << e.name;

    volume::ModalOptions modal = db->parameters().entry.modal;
    modal.material.poissonRatio = options.material.poissonRatio;
    auto expected = volume::correctMorphed(*r->entryPhysics, std::move(*best), modal);
    ASSERT_TRUE(expected.ok()) << e.name << ": " << expected.error().message;
    auto adapted =
        core::adapt(expected->physics, r->normalization, r->massProperties,
                    r->answeredMatch().match.orientation, options.material, db->parameters().entry.damping);
    ASSERT_TRUE(adapted.ok());
    EXPECT_EQ(r->physics->frequenciesHz(), adapted->frequenciesHz()) << e.name;

    // The answer's locator is the corrected tets' (what haptic contact is located in), not the entry's:
    // each tet's centroid, carried from the query's frame to the locator's, is found deep in that tet.
    ASSERT_TRUE(r->locator) << e.name;
    const core::TetMesh& tets = r->physics->tetMesh;
    for (std::size_t t = 0; t < tets.tetCount(); t += 7) {
      core::Vec3 centroid = core::Vec3::Zero();
      for (std::uint32_t node : tets.tets[t])
        centroid += 0.25 * tets.nodes[node];
      const core::TetLocation at = r->locator->locate(r->physics->placement.toEntry(centroid));
      ASSERT_EQ(at.tet, t) << e.name;
      for (double w : at.weights)
        EXPECT_NEAR(w, 0.25, 1e-6) << e.name << " tet " << t;
    }

    // One candidate: the best match, whatever the others' morphs.
    if (checked > 1) continue;
    options.correctionCandidates = 1;
    auto one = db->query(query, options);
    ASSERT_TRUE(one.ok() && one->correction) << e.name;
    EXPECT_EQ(one->answered, 0u);
    EXPECT_EQ(one->correction->morphs, 1);
  }
  EXPECT_GT(checked, 0u);
}

// The correction's guess: a core left waiting for the last candidate's morph computes the modes of the
// best morph so far. On one thread no core waits and no guess is made; on several, guesses are made and
// kept where they stand; every answer is the one thread's, to the bit, fallbacks included.
TEST_F(SmallDatabase, TheCorrectionsGuessOnAWaitingCoreChangesNoAnswer) {
  if (std::thread::hardware_concurrency() < 2)
    GTEST_SKIP() << "needs two cores or more: on one, no core waits for another's morph";
  auto db = Database::open(sPath);
  ASSERT_TRUE(db.ok()) << db.error().message;
  const core::Mat3 stretch = core::Vec3(1.25, 0.8, 0.95).asDiagonal();
  tbb::task_arena one(1);
  std::size_t corrected = 0, guessed = 0;
  for (std::size_t n = 0; n < db->entries().size(); n += 2) {
    const EntryRecord& e = db->entries()[n];
    const core::TriangleMesh query = stretchedSurface(*db, e, stretch);
    const QueryOptions options = correctedAmongThree();
    std::optional<Result<QueryResult>> alone;
    one.execute([&] { alone.emplace(db->query(query, options)); });
    auto shared = db->query(query, options);
    ASSERT_TRUE(alone->ok() && shared.ok()) << e.name;
    const QueryResult& a = **alone;
    ASSERT_EQ(a.correction.has_value(), shared->correction.has_value()) << e.name;
    EXPECT_EQ(a.answered, shared->answered) << e.name;
    EXPECT_EQ(a.answeredMatch().match.entry, shared->answeredMatch().match.entry) << e.name;
    EXPECT_EQ(a.physics->frequenciesHz(), shared->physics->frequenciesHz()) << e.name;
    EXPECT_EQ(a.physics->modeShapes, shared->physics->modeShapes) << e.name;
    EXPECT_EQ(a.physics->tetMesh.nodes, shared->physics->tetMesh.nodes) << e.name;
    if (!a.correction) continue;
    ++corrected;
    const volume::CorrectionReport &x = *a.correction, &y = *shared->correction;
    EXPECT_FALSE(x.speculative) << e.name;
    EXPECT_EQ(x.morph.meanTargetDistance, y.morph.meanTargetDistance) << e.name;
    EXPECT_EQ(x.massScale, y.massScale) << e.name;
    EXPECT_EQ(x.strayShare, y.strayShare) << e.name;
    EXPECT_EQ(x.pointMassPeak, y.pointMassPeak) << e.name;
    EXPECT_EQ(x.massSpread, y.massSpread) << e.name;
    EXPECT_EQ(x.solves, y.solves) << e.name;
    EXPECT_EQ(x.morphs, y.morphs) << e.name;
    EXPECT_EQ(x.fallback, y.fallback) << e.name;
    guessed += y.speculative;
  }
  std::printf("  %zu of %zu corrections guessed on a waiting core\n", guessed, corrected);
  EXPECT_GT(corrected, 0u);
  EXPECT_GT(guessed, 0u) << "no correction of " << corrected << " was guessed on a waiting core";
}

// Thin plates with holes (1:50, trays or sheet-metal parts) against a database of rings, boxes and
// cylinders: where the best of the three nearest entries' morphs leaves a plate unfilled, the correction
// morphs the three nearest by shape alone and the nearest box as well, and the best of those that draw no
// warning answers. Against an oracle of independent morphs and searches; without the fallback, the
// candidates' answer and its warning.
TEST(Database, WhereTheNearestEntriesMorphsLeaveTheQueryUnfilledTheFallbackAnswers) {
  test::ScratchDir dir("fallback");
  const std::filesystem::path path = dir / "rings-boxes-cylinders.db";
  auto built = buildDatabase(
      path, smallBuild(18, {volume::Family::kRing, volume::Family::kBox, volume::Family::kCylinder}));
  ASSERT_TRUE(built.ok()) << built.error().message;
  ASSERT_EQ(built->failed, 0u);
  auto db = Database::open(path);
  ASSERT_TRUE(db.ok()) << db.error().message;
  std::vector<core::EntryId> boxes;
  for (const EntryRecord& e : db->entries())
    if (e.family == volume::Family::kBox) boxes.push_back(e.id);
  volume::ModalOptions modal = db->parameters().entry.modal;
  std::mt19937_64 rng(5);
  tbb::task_arena one(1);
  int triggered = 0, answered = 0, guessed = 0;
  for (int holes = 1; holes <= 3; ++holes)
    for (std::uint32_t index : {0u, 2u}) {
      volume::ShapeSpec plate;
      plate.family = volume::Family::kHoled;
      plate.index = index;  // the holes' size
      plate.params = core::Vec3(1.0, 0.02, holes);
      auto surface = volume::makeFamilyShape(plate, db->parameters().resolution);
      ASSERT_TRUE(surface.ok()) << surface.error().message;
      const core::TriangleMesh query =
          core::transformed(*surface, test::randomSimilarity(rng, 2.0, 0.5, 2.0));
      const std::string name = std::to_string(holes) + " holes, index " + std::to_string(index);

      QueryOptions options;
      options.fidelity = false;
      options.correct = true;
      auto r = db->query(query, options);
      ASSERT_TRUE(r.ok() && r->physics && r->correction)
          << name << ": " << (r ? "no correction" : r.error().message);
      modal.material.poissonRatio = options.material.poissonRatio;
      // On one thread no morph's modes are computed on a guess (TheCorrectionsGuessOnAWaitingCore...):
      // the same answer.
      std::optional<Result<QueryResult>> alone;
      one.execute([&] { alone.emplace(db->query(query, options)); });
      ASSERT_TRUE(alone->ok() && (*alone)->correction) << name;
      EXPECT_FALSE((*alone)->correction->speculative) << name;
      EXPECT_EQ((*alone)->answered, r->answered) << name;
      EXPECT_EQ((*alone)->physics->frequenciesHz(), r->physics->frequenciesHz()) << name;
      guessed += r->correction->speculative;

      // Each entry morphed on its own, onto the query carried into its frame.
      const auto morphOnto = [&](const core::Match& match) {
        return morphOntoQuery(*db, *r, query, match, options.correction);
      };
      std::optional<volume::MorphedEntry> best;
      std::vector<core::EntryId> seen;
      for (std::size_t i = 0; i < 3; ++i) {
        seen.push_back(r->matches[i].match.entry);
        auto morphed = morphOnto(r->matches[i].match);
        if (morphed && (!best || volume::betterMorph(morphed->report, best->report)))
          best = std::move(morphed).value();
      }
      ASSERT_TRUE(best.has_value()) << name;
      if (best->report.massScale <= volume::kMassScaleWarning) {
        EXPECT_FALSE(r->correction->fallback) << name;
        EXPECT_EQ(r->correction->morphs, 3) << name;
        continue;
      }
      ++triggered;

      // The fallback's entries: the three nearest by shape alone and the nearest box, not morphed yet.
      std::vector<core::Match> more;
      core::SearchOptions shape;
      shape.k = 6;
      shape.momentWeight = 0.0;
      auto byShape = db->match(query, DescriptorKind::kCentroidVoxel, shape);
      ASSERT_TRUE(byShape.ok());
      for (const core::Match& m : *byShape)
        if (more.size() < 3 && std::find(seen.begin(), seen.end(), m.entry) == seen.end()) {
          more.push_back(m);
          seen.push_back(m.entry);
        }
      core::SearchOptions among;
      among.among = boxes;
      auto box = db->match(query, DescriptorKind::kCentroidVoxel, among);
      ASSERT_TRUE(box.ok() && box->size() == 1);
      if (std::find(seen.begin(), seen.end(), box->front().entry) == seen.end()) more.push_back(box->front());
      EXPECT_EQ(r->correction->morphs, 3 + static_cast<int>(more.size())) << name;
      std::optional<volume::MorphedEntry> fallback;
      std::optional<core::Match> fallbackMatch;
      for (const core::Match& m : more) {
        auto morphed = morphOnto(m);
        if (!morphed || !volume::correctionWarnings(morphed->report).empty()) continue;
        if (!fallback || volume::betterMorph(morphed->report, fallback->report)) {
          fallback = std::move(morphed).value();
          fallbackMatch = m;
        }
      }
      if (!fallback) {
        EXPECT_FALSE(r->correction->fallback) << name;
        EXPECT_LT(r->answered, 3u) << name;
        EXPECT_EQ(r->correction->massScale, best->report.massScale) << name;
        continue;
      }
      ++answered;
      EXPECT_TRUE(r->correction->fallback) << name;
      EXPECT_EQ(r->answered, r->matches.size() - 1) << name;
      EXPECT_EQ(r->answeredMatch().match.entry, fallbackMatch->entry) << name;
      EXPECT_EQ(r->answeredMatch().match.distance, fallbackMatch->distance) << name;
      EXPECT_TRUE(r->physics->warnings.empty()) << name << ": " << r->physics->warnings.front();
      auto expected =
          volume::correctMorphed(**db->physics(fallbackMatch->entry), std::move(*fallback), modal);
      ASSERT_TRUE(expected.ok()) << expected.error().message;
      auto adapted =
          core::adapt(expected->physics, r->normalization, r->massProperties, fallbackMatch->orientation,
                      options.material, db->parameters().entry.damping);
      ASSERT_TRUE(adapted.ok());
      EXPECT_EQ(r->physics->frequenciesHz(), adapted->frequenciesHz()) << name;

      // Without the fallback: the candidates' best morph, and the warning that it leaves the plate unfilled.
      options.correctionFallback = false;
      auto without = db->query(query, options);
      ASSERT_TRUE(without.ok() && without->correction);
      EXPECT_FALSE(without->correction->fallback);
      EXPECT_LT(without->answered, 3u);
      EXPECT_EQ(without->correction->massScale, best->report.massScale);
      ASSERT_FALSE(without->physics->warnings.empty());
      EXPECT_NE(without->physics->warnings.back().find("hold"), std::string::npos)
          << without->physics->warnings.back();
    }
  std::cout << "  " << triggered << " of 6 plates left unfilled by their candidates, " << answered
            << " answered by the fallback, " << guessed << " on a guess\n";
  EXPECT_GT(answered, 0);
  // Where the candidates send the correction to its fallback they make no guess: the guesses that stood
  // here are the fallback's own (on one core none is made).
  if (std::thread::hardware_concurrency() >= 2) {
    EXPECT_GT(guessed, 0);
  }
}

// A burst (queryMany) against the oracle of one query at a time: every entry's surface under a random
// similarity, in a shuffled order, some twice, with an open surface among them (its error in its own slot),
// through a cache smaller than the burst so that the tasks miss and fill it concurrently.
TEST_F(SmallDatabase, ABurstIsAnsweredInInputOrderExactlyAsEachMeshAlone) {
  Database::OpenOptions small;
  small.cacheEntries = 4;
  auto db = Database::open(sPath, small);
  ASSERT_TRUE(db.ok());
  std::mt19937_64 rng(11);
  std::vector<core::TriangleMesh> burst = ownSurfacesUnderSimilarities(*db, rng);
  std::shuffle(burst.begin(), burst.end(), rng);
  for (std::size_t i = 0; i < 4; ++i)
    burst.push_back(burst[i]);
  core::TriangleMesh open = burst[2];
  open.triangles.pop_back();
  burst.insert(burst.begin() + 5, open);

  QueryOptions options;
  options.search.k = 3;
  const std::vector<Result<QueryResult>> many = db->queryMany(burst, options);
  ASSERT_EQ(many.size(), burst.size());
  for (std::size_t i = 0; i < burst.size(); ++i) {
    SCOPED_TRACE("mesh " + std::to_string(i));
    const Result<QueryResult> alone = db->query(burst[i], options);
    ASSERT_EQ(many[i].ok(), alone.ok());
    if (!alone.ok()) {
      EXPECT_EQ(many[i].error().message, alone.error().message);
      continue;
    }
    const QueryResult &a = *alone, &b = *many[i];
    ASSERT_EQ(b.matches.size(), a.matches.size());
    for (std::size_t m = 0; m < a.matches.size(); ++m) {
      EXPECT_EQ(b.matches[m].match.entry, a.matches[m].match.entry);
      EXPECT_EQ(b.matches[m].match.distance, a.matches[m].match.distance);
      EXPECT_EQ(b.matches[m].match.orientation, a.matches[m].match.orientation);
      ASSERT_TRUE(a.matches[m].fidelity && b.matches[m].fidelity);
      EXPECT_EQ(b.matches[m].fidelity->meanDeviation, a.matches[m].fidelity->meanDeviation);
    }
    ASSERT_TRUE(a.physics && b.physics);
    EXPECT_EQ(b.physics->frequenciesHz(), a.physics->frequenciesHz());
    EXPECT_EQ(b.physics->tetMesh.nodes, a.physics->tetMesh.nodes);
    ASSERT_EQ(b.link.locations.size(), a.link.locations.size());
    for (std::size_t v = 0; v < a.link.locations.size(); ++v) {
      EXPECT_EQ(b.link.locations[v].tet, a.link.locations[v].tet);
      EXPECT_EQ(b.link.locations[v].weights, a.link.locations[v].weights);
    }
    EXPECT_EQ(b.predictedFrequencyError, a.predictedFrequencyError);
  }
  EXPECT_FALSE(many[5].ok());
  EXPECT_TRUE(db->queryMany({}, options).empty());
}

// Opened with one descriptor kind, the database builds that index alone and answers by it exactly as a
// database opened with all three does; a query by another kind is a clear error.
TEST_F(SmallDatabase, OpenedWithOneDescriptorKindItAnswersByThatOneExactly) {
  auto all = Database::open(sPath);
  ASSERT_TRUE(all.ok()) << all.error().message;
  Database::OpenOptions one;
  one.descriptors = {core::DescriptorKind::kCentroidVoxel};
  auto db = Database::open(sPath, one);
  ASSERT_TRUE(db.ok()) << db.error().message;
  EXPECT_TRUE(db->hasIndex(core::DescriptorKind::kCentroidVoxel));
  EXPECT_FALSE(db->hasIndex(core::DescriptorKind::kMoment));
  EXPECT_FALSE(db->hasIndex(core::DescriptorKind::kVoxel));
  std::mt19937_64 rng(5);
  QueryOptions options;
  options.search.k = 3;
  options.fidelity = false;
  for (const core::TriangleMesh& mesh : ownSurfacesUnderSimilarities(*db, rng)) {
    Result<QueryResult> a = all->query(mesh, options), b = db->query(mesh, options);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(b->matches.size(), a->matches.size());
    for (std::size_t m = 0; m < a->matches.size(); ++m) {
      EXPECT_EQ(b->matches[m].match.entry, a->matches[m].match.entry);
      EXPECT_EQ(b->matches[m].match.distance, a->matches[m].match.distance);
    }
    EXPECT_EQ(b->physics->frequenciesHz(), a->physics->frequenciesHz());
  }
  options.descriptor = core::DescriptorKind::kMoment;
  Result<QueryResult> refused = db->query(core::makeBox({1.0, 0.5, 0.25}), options);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(refused.error().message.find("opened without its moment index"), std::string::npos)
      << refused.error().message;
  one.descriptors.clear();
  EXPECT_EQ(Database::open(sPath, one).error().code, ErrorCode::kInvalidArgument);
}

TEST(BuildParametersJson, ElementOrderRoundTripsAndOlderFilesAreLinear) {
  BuildParameters quadratic;
  quadratic.families = {volume::Family::kBox};
  quadratic.entry = volume::withElements(quadratic.entry, volume::ElementOrder::kQuadratic);
  Result<BuildParameters> back = parseBuildParameters(toJson(quadratic));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->entry.modal.order, volume::ElementOrder::kQuadratic);
  EXPECT_EQ(back->entry.tetgen.maxRadiusEdgeRatio, 3.0);
  EXPECT_EQ(back->entry.tetgen.maxVolumeFraction, 1.0 / 100.0);

  // A file written before the element order was stored: linear, as everything then was.
  nlohmann::json older = nlohmann::json::parse(toJson(quadratic));
  older["modes"].erase("elements");
  back = parseBuildParameters(older.dump());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->entry.modal.order, volume::ElementOrder::kLinear);
  older["modes"]["elements"] = "cubic";
  back = parseBuildParameters(older.dump());
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("element order"), std::string::npos) << back.error().message;
}

TEST(BuildParametersJson, StoneSubdivisionsRoundTripAndOlderFilesHaveTwo) {
  BuildParameters quadratic = withElements(BuildParameters{}, volume::ElementOrder::kQuadratic);
  quadratic.families = {volume::Family::kStone};
  EXPECT_EQ(quadratic.resolution.stoneSubdivisions, 1);
  EXPECT_EQ(withElements(quadratic, volume::ElementOrder::kLinear).resolution.stoneSubdivisions, 2);
  Result<BuildParameters> back = parseBuildParameters(toJson(quadratic));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->resolution.stoneSubdivisions, 1);

  // A file written before the subdivisions were stored made its stones from 320 triangles: a resumed
  // build of it makes the rest the same way.
  nlohmann::json older = nlohmann::json::parse(toJson(quadratic));
  older["resolution"].erase("stone_subdivisions");
  back = parseBuildParameters(older.dump());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->resolution.stoneSubdivisions, 2);
  older["resolution"]["stone_subdivisions"] = 9;
  back = parseBuildParameters(older.dump());
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("stone subdivisions"), std::string::npos) << back.error().message;
}

TEST(BuildParametersJson, FamiliesOwnMeshingRoundTripsAndOlderFilesHaveNone) {
  BuildParameters quadratic = withElements(BuildParameters{}, volume::ElementOrder::kQuadratic);
  quadratic.families = {volume::Family::kStone, volume::Family::kUnion};
  EXPECT_EQ(quadratic.resolution.unionTrianglesPerSegment, 12);
  EXPECT_EQ(quadratic.volumeFractions.at(volume::Family::kStone), 3.0 / 100.0);
  const BuildParameters linear = withElements(quadratic, volume::ElementOrder::kLinear);
  EXPECT_EQ(linear.resolution.unionTrianglesPerSegment, 20);
  EXPECT_TRUE(linear.volumeFractions.empty());
  Result<BuildParameters> back = parseBuildParameters(toJson(quadratic));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->resolution.unionTrianglesPerSegment, 12);
  EXPECT_EQ(back->volumeFractions, quadratic.volumeFractions);
  EXPECT_EQ(toJson(*back), toJson(quadratic));

  // A file written before these were stored made its unions from 20 triangles a segment and meshed every
  // family at the entries' bound: a resumed build of it makes the rest the same way.
  nlohmann::json older = nlohmann::json::parse(toJson(quadratic));
  older["resolution"].erase("union_triangles_per_segment");
  older["tetgen"].erase("family_volume_fractions");
  back = parseBuildParameters(older.dump());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->resolution.unionTrianglesPerSegment, 20);
  EXPECT_TRUE(back->volumeFractions.empty());
  EXPECT_EQ(entryOptionsFor(*back, volume::Family::kStone).tetgen.maxVolumeFraction, 1.0 / 100.0);

  older["tetgen"]["family_volume_fractions"] = {{"pebble", 0.03}};
  back = parseBuildParameters(older.dump());
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("pebble"), std::string::npos) << back.error().message;
  older["tetgen"]["family_volume_fractions"] = {{"stone", 0.0}};
  back = parseBuildParameters(older.dump());
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("stone"), std::string::npos) << back.error().message;
}

TEST(BuildParametersJson, TheWallBoundRoundTripsAndOlderFilesHaveNone) {
  BuildParameters walled;
  walled.families = {volume::Family::kBeam};
  walled.entry.tetgen.wallEdgeFraction = 0.7;
  Result<BuildParameters> back = parseBuildParameters(toJson(walled));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->entry.tetgen.wallEdgeFraction, 0.7);

  // A file written before the wall bound existed meshed without one.
  nlohmann::json older = nlohmann::json::parse(toJson(walled));
  older["tetgen"].erase("wall_edge_fraction");
  back = parseBuildParameters(older.dump());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->entry.tetgen.wallEdgeFraction, 0.0);
  older["tetgen"]["wall_edge_fraction"] = -1.0;
  back = parseBuildParameters(older.dump());
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().message.find("wall edge fraction"), std::string::npos) << back.error().message;
}

TEST(BuildParametersJson, FamilyWeightsRoundTripAndOlderFilesAreEven) {
  BuildParameters weighted;
  weighted.families = {volume::Family::kBox, volume::Family::kFragment};
  weighted.weights = {1, 4};
  Result<BuildParameters> back = parseBuildParameters(toJson(weighted));
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->weights, weighted.weights);

  // A file written before weights existed: its catalog was even.
  nlohmann::json older = nlohmann::json::parse(toJson(weighted));
  older.erase("weights");
  back = parseBuildParameters(older.dump());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_TRUE(back->weights.empty());
  for (const nlohmann::json& bad : {nlohmann::json{1}, nlohmann::json{1, 0}, nlohmann::json{1, 101}}) {
    older["weights"] = bad;
    back = parseBuildParameters(older.dump());
    ASSERT_FALSE(back.ok()) << bad.dump();
    EXPECT_NE(back.error().message.find("weights"), std::string::npos) << back.error().message;
  }
}

// A file's descriptor grid sizes its index's tables: one outside what a descriptor may have is a foreign
// or damaged file, refused when its parameters are read.
TEST(BuildParametersJson, ADescriptorGridOutOfRangeIsRefused) {
  nlohmann::json stored = nlohmann::json::parse(toJson(BuildParameters{}));
  for (int grid : {0, 1, core::kMaxGridSize + 1, 1000}) {
    stored["descriptor"]["grid"] = grid;
    Result<BuildParameters> back = parseBuildParameters(stored.dump());
    ASSERT_FALSE(back.ok()) << grid;
    EXPECT_NE(back.error().message.find("descriptor grid must be 2 to 64"), std::string::npos)
        << back.error().message;
  }
  stored["descriptor"]["grid"] = core::kMaxGridSize;
  EXPECT_TRUE(parseBuildParameters(stored.dump()).ok());
}

TEST_F(SmallDatabase, OtherDescriptorParametersAreAClearError) {
  core::DescriptorOptions other;
  other.gridSize = 12;
  auto db = Database::open(sPath, {.cacheEntries = 4, .expectDescriptor = other});
  ASSERT_FALSE(db.ok());
  EXPECT_NE(db.error().message.find("grid 10"), std::string::npos) << db.error().message;
}

TEST_F(SmallDatabase, CorruptedTruncatedAndForeignFilesAreClearErrors) {
  // A copy with one physics blob's bytes changed behind its checksum.
  const auto corrupted = sDir->path() / "corrupted.db";
  std::filesystem::copy_file(sPath, corrupted);
  {
    auto store = Store::open(corrupted, true);
    ASSERT_TRUE(store.ok());
  }
  {
    // Flip the blob through SQLite itself, so the file stays a valid SQLite file.
    const std::string sql =
        "sqlite3 " + corrupted.string() +
        " \"UPDATE physics SET data = zeroblob(length(data)) WHERE entry_id = 2 AND part = 2\"";
    ASSERT_EQ(std::system(sql.c_str()), 0) << "needs the sqlite3 shell";
  }
  auto db = Database::open(corrupted);
  ASSERT_TRUE(db.ok()) << db.error().message;  // descriptors are intact
  auto physics = db->physics(2);
  ASSERT_FALSE(physics.ok());
  EXPECT_NE(physics.error().message.find("entry 2: modes: checksum mismatch"), std::string::npos)
      << physics.error().message;
  {
    // The eigenvalues alone, as a query's neighbours are read: the same check, the same message.
    auto store = Store::open(corrupted);
    ASSERT_TRUE(store.ok());
    auto eigenvalues = store->eigenvalues(2);
    ASSERT_FALSE(eigenvalues.ok());
    EXPECT_NE(eigenvalues.error().message.find("entry 2: modes: checksum mismatch"), std::string::npos)
        << eigenvalues.error().message;
    EXPECT_TRUE(store->eigenvalues(1).ok());
    auto missing = store->eigenvalues(100000);
    ASSERT_FALSE(missing.ok());
    EXPECT_NE(missing.error().message.find("entry 100000: no such entry"), std::string::npos)
        << missing.error().message;
  }

  // Truncated to half its size: SQLite notices, we say which file.
  const auto truncated = sDir->path() / "truncated.db";
  std::filesystem::copy_file(sPath, truncated);
  std::filesystem::resize_file(truncated, std::filesystem::file_size(truncated) / 2);
  auto t = Database::open(truncated);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().message.find("truncated.db"), std::string::npos) << t.error().message;

  // Not a database at all, and another application's SQLite file.
  const auto text = sDir->path() / "notes.db";
  test::writeFile(text, "these are not the entries you are looking for\n");
  auto n = Database::open(text);
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.error().message.find("not a database"), std::string::npos) << n.error().message;
  const auto foreign = sDir->path() / "foreign.db";
  ASSERT_EQ(std::system(("sqlite3 " + foreign.string() + " \"CREATE TABLE t(x)\"").c_str()), 0);
  auto f = Database::open(foreign);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("not a shapedb database"), std::string::npos) << f.error().message;

  // Another schema version.
  const auto future = sDir->path() / "future.db";
  std::filesystem::copy_file(sPath, future);
  ASSERT_EQ(std::system(("sqlite3 " + future.string() + " \"PRAGMA user_version = 99\"").c_str()), 0);
  auto v = Database::open(future);
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().message.find("schema version 99"), std::string::npos) << v.error().message;
}

TEST(Database, BuildRefusesToOverwriteAndResumeNeedsAFile) {
  test::ScratchDir dir("database-guards");
  const auto path = dir / "a.db";
  BuildOptions options = smallBuild(2, {volume::Family::kBox}, 2);
  ASSERT_TRUE(buildDatabase(path, options).ok());
  auto again = buildDatabase(path, options);
  ASSERT_FALSE(again.ok());
  EXPECT_NE(again.error().message.find("already exists"), std::string::npos);
  options.resume = true;
  auto resumed = buildDatabase(path, options);  // complete: nothing to do
  ASSERT_TRUE(resumed.ok());
  EXPECT_EQ(resumed->built, 0u);
  EXPECT_EQ(resumed->skipped, 2u);
  auto missing = buildDatabase(dir / "b.db", options);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("no database to resume"), std::string::npos);
}

TEST(Database, AddedMeshesAreFoundAndAnOpenOneIsRefusedWithNothingWritten) {
  test::ScratchDir dir("database-add");
  const auto path = dir / "a.db";
  ASSERT_TRUE(buildDatabase(path, smallBuild(2, {volume::Family::kBox}, 2)).ok());
  const core::TriangleMesh wedge = core::makeTriangularPrism(1.0, 0.4, 3.0);
  core::TriangleMesh open = core::makeBox(core::Vec3(1, 2, 3));
  open.triangles.pop_back();
  const std::vector<NamedMesh> bad = {{"wedge.obj", "wedge.obj", wedge}, {"open.obj", "open.obj", open}};
  auto refused = addToDatabase(path, bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("open.obj"), std::string::npos) << refused.error().message;
  EXPECT_EQ(Database::open(path)->entries().size(), 2u);  // all or none

  auto ids = addToDatabase(path, std::span(bad).first(1));
  ASSERT_TRUE(ids.ok()) << ids.error().message;
  ASSERT_EQ(ids->size(), 1u);
  EXPECT_EQ(ids->front(), 2u);
  auto db = Database::open(path);
  ASSERT_TRUE(db.ok());
  EXPECT_EQ(db->entry(2)->family, volume::Family::kUser);
  std::mt19937_64 rng(5);
  auto matches =
      db->match(core::transformed(wedge, test::randomSimilarity(rng)), DescriptorKind::kCentroidVoxel);
  ASSERT_TRUE(matches.ok());
  EXPECT_EQ(matches->front().entry, 2u);
  auto duplicate = addToDatabase(path, std::span(bad).first(1));
  ASSERT_FALSE(duplicate.ok());
  EXPECT_NE(duplicate.error().message.find("already in the database"), std::string::npos);
  // Names are checked before anything is computed: an open surface under a taken name is refused for
  // its name, and so are two meshes of one name.
  const std::vector<NamedMesh> taken = {{"wedge.obj", "elsewhere/wedge.obj", open}};
  auto refusedByName = addToDatabase(path, taken);
  ASSERT_FALSE(refusedByName.ok());
  EXPECT_NE(refusedByName.error().message.find("elsewhere/wedge.obj: an entry named 'wedge.obj' is already"),
            std::string::npos)
      << refusedByName.error().message;
  const std::vector<NamedMesh> twice = {{"a.obj", "a.obj", wedge}, {"a.obj", "b/a.obj", wedge}};
  auto refusedTwice = addToDatabase(path, twice);
  ASSERT_FALSE(refusedTwice.ok());
  EXPECT_NE(refusedTwice.error().message.find("given twice"), std::string::npos);
  EXPECT_EQ(Database::open(path)->entries().size(), 3u);
}

// A hollow object (a cavity: an inner shell wound inward) and two solids in one mesh: the catalog's
// entries are single solids without cavities, so the answer says what it is of and carries no predicted
// error (the error model knows single solids only; an unknown error is one enrichment learns from). Added
// to the database, the hollow object is meshed with its cavity empty, and it then answers for itself
// with a prediction and without the warning.
TEST(Database, CavitiesAndSeparateSolidsAreSaidAndLearnedObjectsKeepTheirCavities) {
  test::ScratchDir dir("database-shells");
  const auto path = dir / "a.db";
  ASSERT_TRUE(buildDatabase(path, smallBuild(2, {volume::Family::kBox}, 2)).ok());
  const core::TriangleMesh box = core::makeBox(core::Vec3(1.0, 0.8, 0.6));
  const core::TriangleMesh hollow =
      test::withShell(box, core::makeBox(core::Vec3(0.7, 0.5, 0.3)), core::Vec3::Zero(), true);
  const core::TriangleMesh apart = test::withShell(box, box, core::Vec3(2.0, 0.0, 0.0), false);
  QueryOptions options;
  options.fidelity = true;
  options.link = true;
  const auto warned = [](const QueryResult& r, const std::string& what) {
    return std::any_of(r.physics->warnings.begin(), r.physics->warnings.end(),
                       [&](const std::string& w) { return w.find(what) != std::string::npos; });
  };
  {
    auto db = Database::open(path);
    ASSERT_TRUE(db.ok()) << db.error().message;
    auto single = db->query(box, options);
    ASSERT_TRUE(single.ok() && single->physics) << (single ? "" : single.error().message);
    EXPECT_TRUE(single->predictedFrequencyError.has_value());
    EXPECT_FALSE(warned(*single, "cavit"));
    auto h = db->query(hollow, options);
    ASSERT_TRUE(h.ok() && h->physics) << (h ? "" : h.error().message);
    EXPECT_TRUE(warned(*h, "encloses 1 cavity"));
    EXPECT_FALSE(h->predictedFrequencyError.has_value());
    auto two = db->query(apart, options);
    ASSERT_TRUE(two.ok() && two->physics) << (two ? "" : two.error().message);
    EXPECT_TRUE(warned(*two, "2 closed shells wound outward"));
    EXPECT_TRUE(warned(*two, "the largest holds 50 % of their volume"));
    EXPECT_FALSE(warned(*two, "overlap"));
    EXPECT_FALSE(two->predictedFrequencyError.has_value());
    // Two parts that overlap: said as such, the overlap counted twice in the volume.
    const core::TriangleMesh overlapping = test::twoUnitBoxes(core::Vec3(0.5, 0.3, 0.2));
    auto crossed = db->query(overlapping, options);
    ASSERT_TRUE(crossed.ok() && crossed->physics) << (crossed ? "" : crossed.error().message);
    EXPECT_TRUE(warned(*crossed, "2 closed shells wound outward that pass through each other"));
    EXPECT_TRUE(warned(*crossed, "count the overlap twice"));
    EXPECT_NEAR(crossed->massProperties.volume, 2.0, 1e-12);  // the union holds 1.72
    EXPECT_FALSE(crossed->predictedFrequencyError.has_value());
  }
  auto ids = addToDatabase(path, std::vector<NamedMesh>{{"hollow.obj", "hollow.obj", hollow}});
  ASSERT_TRUE(ids.ok()) << ids.error().message;
  auto db = Database::open(path);
  ASSERT_TRUE(db.ok()) << db.error().message;
  auto physics = db->physics(ids->front());
  ASSERT_TRUE(physics.ok()) << physics.error().message;
  // In the entry's canonical frame the solid has unit volume: with the cavity filled, 0.48 / 0.375 of it.
  EXPECT_NEAR(core::computeTetMassProperties((*physics)->tetMesh).volume, 1.0, 1e-6);
  auto h = db->query(hollow, options);
  ASSERT_TRUE(h.ok() && h->physics) << (h ? "" : h.error().message);
  EXPECT_EQ(h->answeredMatch().match.entry, ids->front());
  EXPECT_FALSE(warned(*h, "cavit"));
  EXPECT_TRUE(h->predictedFrequencyError.has_value());
}

}  // namespace
}  // namespace shapedb::io

namespace shapedb::io {
namespace {

// A family with a volume bound of its own is meshed with it, and the others with the entries' bound.
TEST(BuildCatalog, AFamilyWithItsOwnVolumeBoundIsMeshedWithIt) {
  BuildParameters p;
  p.entries = 2;
  p.families = {volume::Family::kStone, volume::Family::kBox};
  p.entry.modal.modes = 4;
  ASSERT_EQ(p.volumeFractions.count(volume::Family::kStone), 1u) << "the default build meshes stones coarser";
  const std::vector<volume::ShapeSpec> catalog = volume::buildCatalog(p.entries, p.families);
  ASSERT_EQ(catalog[0].family, volume::Family::kStone);
  BuildParameters even = p;
  even.volumeFractions.clear();
  const detail::ComputedEntry own = detail::computeCatalogEntry(catalog, 0, p);
  const detail::ComputedEntry shared = detail::computeCatalogEntry(catalog, 0, even);
  ASSERT_TRUE(own.data && shared.data);
  EXPECT_LT(own.record.tets, shared.record.tets);
  // The bound is the stones': a box is meshed alike either way.
  const detail::ComputedEntry box = detail::computeCatalogEntry(catalog, 1, p);
  const detail::ComputedEntry sameBox = detail::computeCatalogEntry(catalog, 1, even);
  ASSERT_TRUE(box.data && sameBox.data);
  EXPECT_EQ(box.data->physics, sameBox.data->physics);
}

// A computed entry crosses from the rank that computed it to the one that writes as bytes: they must carry
// the blobs unchanged (the file gets the single build's bytes), a failure with its reason, and nothing that
// is not one of them.
TEST(BuildWire, AComputedEntryCrossesUnchangedAndGarbageIsRefused) {
  BuildParameters p;
  p.entries = 4;
  p.families = {volume::Family::kBox, volume::Family::kCone};
  p.entry.modal.modes = 4;
  const std::vector<volume::ShapeSpec> catalog = volume::buildCatalog(p.entries, p.families);
  const detail::ComputedEntry computed = detail::computeCatalogEntry(catalog, 3, p);
  ASSERT_TRUE(computed.data) << computed.failure->message;
  const std::vector<std::uint8_t> wire = detail::toWire(computed);
  const Result<detail::ComputedEntry> back = detail::fromWire(wire.data(), wire.size());
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->record.id, 3u);
  EXPECT_EQ(back->record.name, catalog[3].name());
  EXPECT_EQ(back->record.family, catalog[3].family);
  EXPECT_EQ(back->record.params, computed.record.params);
  EXPECT_EQ(back->record.nodes, computed.record.nodes);
  EXPECT_EQ(back->record.times.modes, computed.record.times.modes);
  EXPECT_EQ(back->data->descriptors, computed.data->descriptors);
  EXPECT_EQ(back->data->physics, computed.data->physics);
  EXPECT_FALSE(back->failure);

  detail::ComputedEntry failed;
  failed.record.id = 7;
  failed.record.name = "cone-00003";
  failed.failure = FailureRecord{"cone-00003", "TetGen refused it"};
  const std::vector<std::uint8_t> failedWire = detail::toWire(failed);
  const Result<detail::ComputedEntry> failedBack = detail::fromWire(failedWire.data(), failedWire.size());
  ASSERT_TRUE(failedBack.ok());
  EXPECT_FALSE(failedBack->data);
  EXPECT_EQ(failedBack->failure->message, "TetGen refused it");

  // Every truncation, and bytes that run on, are refused; so is random noise.
  for (std::size_t size : {std::size_t{0}, std::size_t{3}, wire.size() / 2, wire.size() - 1})
    EXPECT_EQ(detail::fromWire(wire.data(), size).error().code, ErrorCode::kParse) << size;
  std::vector<std::uint8_t> longer = wire;
  longer.push_back(0);
  EXPECT_FALSE(detail::fromWire(longer.data(), longer.size()).ok());
  std::mt19937_64 rng(5);
  std::vector<std::uint8_t> noise(4096);
  for (std::uint8_t& b : noise)
    b = static_cast<std::uint8_t>(rng());
  EXPECT_FALSE(detail::fromWire(noise.data(), noise.size()).ok());
}

}  // namespace
}  // namespace shapedb::io
