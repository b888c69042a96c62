// The physical-fidelity benchmark on shapes whose answer is known: a shape that is in the database comes
// back with its own data, and a box or an ellipsoid is its own inertia-equivalent baseline.

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/bench/evaluation.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/database.h>
#include <shapedb/volume/families.h>

#include "support/test_support.h"

namespace shapedb::bench {
namespace {

TEST(Evaluation, KnownAnswersForEntriesBoxesAndEllipsoids) {
  test::ScratchDir dir("evaluation");
  const auto path = dir / "small.db";
  io::BuildOptions build;  // quadratic tets, the default
  build.parameters.entries = 8;
  build.parameters.families = {volume::Family::kBox, volume::Family::kEllipsoid};
  build.parameters.entry.modal.modes = 6;
  build.threads = 2;
  auto report = io::buildDatabase(path, build);
  ASSERT_TRUE(report.ok()) << report.error().message;
  auto db = io::Database::open(path);
  ASSERT_TRUE(db.ok()) << db.error().message;

  // An entry's own surface, turned, moved and scaled; a plain box; a smooth ellipsoid.
  const io::EntryRecord& entry = db->entries()[1];
  auto surface = volume::makeFamilyShape(
      volume::familySpec(entry.family,
                         static_cast<std::uint32_t>(std::stoul(entry.name.substr(entry.name.find('-') + 1)))),
      db->parameters().resolution);
  ASSERT_TRUE(surface.ok());
  std::mt19937_64 rng(5);
  std::vector<io::NamedMesh> shapes{
      {"entry", "", core::transformed(*surface, test::randomSimilarity(rng, 2.0, 0.05, 0.2))},
      {"box", "", core::makeBox({0.3, 0.2, 0.1})},
      {"ellipsoid", "", core::makeUvEllipsoid({0.15, 0.1, 0.06}, 24, 12)},
  };
  EvaluationOptions options;
  options.frequencies = 4;
  options.overlapResolution = 40;
  options.truthRefinement = 3.0;  // finer than the entries, and not so fine that the test takes a minute
  std::size_t progressCalls = 0;
  options.progress = [&](std::size_t done, std::size_t total, const std::string&) {
    ++progressCalls;
    EXPECT_LE(done, total);
  };
  auto evaluations = evaluateShapes(*db, shapes, options);
  ASSERT_TRUE(evaluations.ok()) << evaluations.error().message;
  ASSERT_EQ(evaluations->size(), 3u);
  EXPECT_EQ(progressCalls, 3u);
  for (const FragmentEvaluation& e : *evaluations) {
    ASSERT_TRUE(e.ok()) << e.name << ": " << e.error;
    ASSERT_EQ(e.methods.size(), kEvaluationMethods.size());
    ASSERT_EQ(e.truthFrequenciesHz.size(), 4);
    EXPECT_GT(e.truthSeconds, 0.0);
    EXPECT_GT(e.speedup(), 1.0) << e.name;  // a query beats TetGen + FEM + Lanczos on any machine
    for (const MethodEvaluation& m : e.methods) {
      if (m.method != EvaluationMethod::kCentroidVoxelStretched) {  // linear tets only: not here
        EXPECT_EQ(m.frequenciesHz.size(), 4) << e.name << " " << toString(m.method);
      }
      EXPECT_GE(m.overlap.iou, 0.0);
      EXPECT_LE(m.overlap.iou, 1.0);
    }
  }
  // The entry comes back as itself from the centroid-voxel descriptor: answered by its own spectrum, the
  // same data, up to TetGen meshing the moved surface differently and finer.
  const MethodEvaluation& self = (*evaluations)[0].methods[8];
  EXPECT_EQ(self.method, EvaluationMethod::kCentroidVoxelNearest);
  EXPECT_EQ(self.match, entry.name);
  EXPECT_EQ((*evaluations)[0].methods[2].match, entry.name);
  EXPECT_LT(self.maxFrequencyError, 0.03);
  EXPECT_GT(self.overlap.iou, 0.8);  // the compound's own fit to its shape
  // The stretch correction needs linear tets: on this database its column is not evaluated.
  const MethodEvaluation& stretched = (*evaluations)[0].methods[5];
  EXPECT_EQ(stretched.method, EvaluationMethod::kCentroidVoxelStretched);
  EXPECT_TRUE(std::isnan(stretched.firstFrequencyError));
  // The geometry correction is, besides, a solve on the entry's own tets (the entry is its own shape:
  // nothing moves): the same frequencies as the entry's.
  const MethodEvaluation& corrected = (*evaluations)[0].methods[7];
  EXPECT_EQ(corrected.method, EvaluationMethod::kCentroidVoxelCorrected);
  EXPECT_EQ(corrected.match, self.match);
  EXPECT_NEAR(corrected.firstFrequencyError, self.firstFrequencyError, 1e-3);
  EXPECT_GT(corrected.queryMicros, self.queryMicros);
  // Its speedup over the direct computation is reported (how large is the benchmark's to say, not a test's:
  // on this tiny entry the two cost about the same).
  EXPECT_TRUE(std::isfinite((*evaluations)[0].correctedSpeedup()));
  EXPECT_GT((*evaluations)[0].correctedSpeedup(), 0.0);
  // Corrected, the box query (3:2:1, which no entry is) takes the box's own frequencies, within what the
  // entry's coarser tets, morphed, can hold.
  const MethodEvaluation& boxCorrected = (*evaluations)[1].methods[7];
  std::printf("3:2:1 box: f1 error %+.1f %% uncorrected, %+.2f %% corrected\n",
              100.0 * (*evaluations)[1].methods[8].firstFrequencyError,
              100.0 * boxCorrected.firstFrequencyError);
  EXPECT_LT(boxCorrected.maxFrequencyError, 0.05);
  EXPECT_LT(std::abs(boxCorrected.firstFrequencyError),
            std::abs((*evaluations)[1].methods[8].firstFrequencyError));
  // The box is its own inertia-equivalent box, and the ellipsoid nearly its own ellipsoid.
  const MethodEvaluation& box = (*evaluations)[1].methods[4];
  EXPECT_LT(box.maxFrequencyError, 0.03);
  EXPECT_GT(box.overlap.iou, 0.95);
  const MethodEvaluation& ellipsoid = (*evaluations)[2].methods[3];
  EXPECT_LT(ellipsoid.maxFrequencyError, 0.03);
  EXPECT_GT(ellipsoid.overlap.iou, 0.95);
  // And not the other way round: an ellipsoid is no box.
  EXPECT_GT(std::abs((*evaluations)[2].methods[4].firstFrequencyError), 0.05);

  // The files: one CSV row per shape and method, a summary naming every method, two PNGs.
  ASSERT_TRUE(writeEvaluationCsv(*evaluations, dir / "e.csv").ok());
  ASSERT_TRUE(writeEvaluationSummary(*evaluations, "test", dir / "summary.md").ok());
  ASSERT_TRUE(writeEvaluationPlots(*evaluations, dir.path()).ok());
  std::ifstream csv(dir / "e.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(csv, line))
    ++rows;
  EXPECT_EQ(rows, 1 + 3 * kEvaluationMethods.size());
  std::ifstream md(dir / "summary.md");
  const std::string summary((std::istreambuf_iterator<char>(md)), {});
  for (EvaluationMethod m : kEvaluationMethods)
    EXPECT_NE(summary.find(std::string("| ") + toString(m) +
                           (m == EvaluationMethod::kCentroidVoxelStretched ? " | 0 |" : " | 3 |")),
              std::string::npos)
        << summary;
  for (const char* png : {"time.png", "error.png"})
    EXPECT_GT(std::filesystem::file_size(dir / png), 1000u) << png;

  // The direct computations on quadratic tets (the default): a thin plate's truth drops against linear
  // ones (which lock in bending), and the plate is still its own box baseline.
  const std::vector<io::NamedMesh> plate{{"plate", "", core::makeBox({0.3, 0.2, 0.03})}};
  options.progress = nullptr;
  auto quadratic = evaluateShapes(*db, plate, options);
  options.directElements = volume::ElementOrder::kLinear;
  auto linear = evaluateShapes(*db, plate, options);
  ASSERT_TRUE(linear.ok() && quadratic.ok());
  ASSERT_TRUE(linear->front().ok() && quadratic->front().ok())
      << linear->front().error << quadratic->front().error;
  std::printf("plate truth f1: linear %.1f Hz, quadratic %.1f Hz\n", linear->front().truthFrequenciesHz[0],
              quadratic->front().truthFrequenciesHz[0]);
  EXPECT_LT(quadratic->front().truthFrequenciesHz[0], 0.9 * linear->front().truthFrequenciesHz[0]);
  EXPECT_LT(quadratic->front().methods[4].maxFrequencyError, 0.03);
  options.directElements = volume::ElementOrder::kQuadratic;

  // Bad options are errors before any work.
  options.frequencies = 7;  // the database has 6 modes
  EXPECT_EQ(evaluateShapes(*db, shapes, options).error().code, ErrorCode::kInvalidArgument);
  options.frequencies = 5;
  options.correctionCandidates = 0;
  EXPECT_EQ(evaluateShapes(*db, shapes, options).error().code, ErrorCode::kInvalidArgument);
}

/// A small database's build: `entries` boxes of four modes.
io::BuildOptions boxes(std::size_t entries) {
  io::BuildOptions build;
  build.parameters.entries = entries;
  build.parameters.families = {volume::Family::kBox};
  build.parameters.entry.modal.modes = 4;
  return build;
}

TEST(Evaluation, AShapeThatCannotBeQueriedIsReportedAndTheOthersGoOn) {
  test::ScratchDir dir("evaluation-bad");
  const auto path = dir / "small.db";
  auto report = io::buildDatabase(path, boxes(4));
  ASSERT_TRUE(report.ok()) << report.error().message;
  auto db = io::Database::open(path);
  ASSERT_TRUE(db.ok());
  core::TriangleMesh open = core::makeBox({1, 1, 1});
  open.triangles.pop_back();
  const std::vector<io::NamedMesh> shapes{{"open", "", open}, {"box", "", core::makeBox({0.2, 0.1, 0.1})}};
  EvaluationOptions options;
  options.frequencies = 4;
  auto evaluations = evaluateShapes(*db, shapes, options);
  ASSERT_TRUE(evaluations.ok()) << evaluations.error().message;
  EXPECT_FALSE((*evaluations)[0].ok());
  EXPECT_NE((*evaluations)[0].error.find("query"), std::string::npos) << (*evaluations)[0].error;
  EXPECT_TRUE((*evaluations)[1].ok()) << (*evaluations)[1].error;
  ASSERT_TRUE(writeEvaluationCsv(*evaluations, dir / "e.csv").ok());
  std::ifstream csv(dir / "e.csv");
  const std::string text((std::istreambuf_iterator<char>(csv)), {});
  EXPECT_NE(text.find("open,"), std::string::npos);
  EXPECT_NE(text.find("query"), std::string::npos);
  // Every row, the failed shape's too, has the header's fields (commas outside quotes).
  std::istringstream lines(text);
  std::vector<std::size_t> fields;
  for (std::string line; std::getline(lines, line);) {
    std::size_t commas = 0;
    bool quoted = false;
    for (const char c : line) {
      if (c == '"') quoted = !quoted;
      if (c == ',' && !quoted) ++commas;
    }
    fields.push_back(commas + 1);
  }
  ASSERT_GT(fields.size(), 2u);
  for (std::size_t i = 1; i < fields.size(); ++i)
    EXPECT_EQ(fields[i], fields[0]) << "row " << i;
}

TEST(Evaluation, TheWarmUpRunsOnAnInstanceOfItsOwnAndChangesNoAnswer) {
  test::ScratchDir dir("evaluation-warm-up");
  const auto path = dir / "small.db";
  ASSERT_TRUE(io::buildDatabase(path, boxes(4)).ok());
  const std::vector<io::NamedMesh> shapes{{"brick", "", core::makeBox({0.2, 0.1, 0.05})},
                                          {"bar", "", core::makeBox({0.3, 0.04, 0.03})}};
  EvaluationOptions options;
  options.frequencies = 4;

  auto cold = io::Database::open(path);
  ASSERT_TRUE(cold.ok());
  auto withoutWarmUp = evaluateShapes(*cold, shapes, options);
  ASSERT_TRUE(withoutWarmUp.ok()) << withoutWarmUp.error().message;

  auto timed = io::Database::open(path);
  auto other = io::Database::open(path);
  ASSERT_TRUE(timed.ok() && other.ok());
  options.warmUp = &*other;
  auto withWarmUp = evaluateShapes(*timed, shapes, options);
  ASSERT_TRUE(withWarmUp.ok()) << withWarmUp.error().message;

  // The warm-up queried its own instance; the timed one fetched every entry itself, as without it.
  EXPECT_GT(other->cacheStats()[1], 0u);
  EXPECT_EQ(timed->cacheStats(), cold->cacheStats());
  // And every method answered as without it, to the bit.
  ASSERT_EQ(withWarmUp->size(), shapes.size());
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const FragmentEvaluation &a = (*withoutWarmUp)[i], &b = (*withWarmUp)[i];
    ASSERT_TRUE(a.ok() && b.ok()) << a.error << b.error;
    ASSERT_EQ(a.methods.size(), b.methods.size());
    for (std::size_t m = 0; m < a.methods.size(); ++m) {
      ASSERT_EQ(a.methods[m].frequenciesHz.size(), b.methods[m].frequenciesHz.size());
      for (Eigen::Index f = 0; f < a.methods[m].frequenciesHz.size(); ++f)
        EXPECT_EQ(a.methods[m].frequenciesHz[f], b.methods[m].frequenciesHz[f])
            << shapes[i].name << " " << toString(a.methods[m].method) << " frequency " << f;
      EXPECT_EQ(a.methods[m].match, b.methods[m].match);
    }
  }

  // The timed instance itself, or an instance of another file, is refused before any work.
  options.warmUp = &*timed;
  EXPECT_EQ(evaluateShapes(*timed, shapes, options).error().code, ErrorCode::kInvalidArgument);
  ASSERT_TRUE(io::buildDatabase(dir / "smaller.db", boxes(3)).ok());
  auto smaller = io::Database::open(dir / "smaller.db");
  ASSERT_TRUE(smaller.ok());
  options.warmUp = &*smaller;
  auto refused = evaluateShapes(*timed, shapes, options);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("same file"), std::string::npos) << refused.error().message;
}

}  // namespace
}  // namespace shapedb::bench
