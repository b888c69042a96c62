// What the geometry correction (volume/correction.h) costs per database entry: every k-th entry's tets
// morphed onto its own surface under a random stretch (each axis of a random rotation scaled by a factor
// in [0.85, 1.15]), then the modes computed again on them, with the database's modal options, as a query
// with --correct --correct-candidates 1 does. Per family and over all the entries sampled (an even sample
// of the catalog, so its medians are a default entry's): the entry's tets and the quadratic mesh's degrees
// of freedom, the morph's and the modes' median time, the median and mean count of the modes' solves with
// the factorized K − σM (one per vector of a block), and the whole correction's median and p90
// (milliseconds).
// With --check, each correction's modes are also computed as an entry's are (computeModes: a random start,
// converged to 1e-10, outside the timings), and the bench reports how far the correction's are from them:
// the largest relative difference of the twenty frequencies, and of the shapes 1 − MAC (the squared
// cosine between the two, at the corners) over the modes whose neighbours' frequencies are over 1 % away
// (a closer pair's shapes are any basis of their plane).
// Run it on one core (taskset -c 0): a query corrects on one, and so does a haptic worker. Freed memory is
// kept in the heap as the command-line tool keeps it (cli/main.cpp): otherwise page faults on the
// matrices' fresh blocks add ~40 % to the modes of a small entry on a VM.
//   build/release/bin/correction_bench DB [--every K] [--seed S] [--check]

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <shapedb/core/physics.h>
#include <shapedb/core/statistics.h>
#include <shapedb/io/database.h>
#include <shapedb/volume/correction.h>
#include <shapedb/volume/families.h>

#include "synthetic.h"

namespace {

using namespace shapedb;

struct Sample {
  std::size_t tets = 0;
  double dof = 0.0, morphMs = 0.0, modesMs = 0.0;
  int solves = 0;  ///< Lanczos's solves with the factorized K − σM (CorrectionReport::solves)
  double frequencyError = 0.0, shapeError = 0.0;  ///< against computeModes, with --check
};

// The largest relative difference of the frequencies of `a` and `b` (the same modes), and the largest
// 1 − MAC of their shapes over the modes isolated in `b` by over 1 % in frequency.
std::pair<double, double> modeDifference(const core::ModalData& a, const core::ModalData& b) {
  double frequency = 0.0, shape = 0.0;
  const Eigen::Index m = std::min(a.eigenvalues.size(), b.eigenvalues.size());
  for (Eigen::Index i = 0; i < m; ++i) {
    frequency = std::max(frequency, std::abs(std::sqrt(a.eigenvalues[i] / b.eigenvalues[i]) - 1.0));
    const bool isolated = (i == 0 || b.eigenvalues[i] > 1.01 * b.eigenvalues[i - 1]) &&
                          (i + 1 == m || b.eigenvalues[i + 1] > 1.01 * b.eigenvalues[i]);
    if (!isolated) continue;
    const double c = a.shapes.col(i).dot(b.shapes.col(i));
    shape = std::max(shape, 1.0 - c * c / (a.shapes.col(i).squaredNorm() * b.shapes.col(i).squaredNorm()));
  }
  return {frequency, shape};
}

// The stretch: a random rotation's axes scaled by factors in [0.85, 1.15], about the origin (the entry's
// centre of mass in its canonical frame).
core::Mat3 randomStretch(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> factor(0.85, 1.15);
  const core::Mat3 r = test::randomRotation(rng);
  const core::Vec3 s(factor(rng), factor(rng), factor(rng));
  return r * s.asDiagonal() * r.transpose();
}

void printRow(const std::string& name, const std::vector<Sample>& samples, bool check) {
  std::vector<double> tets, dof, morph, modes, total, solves;
  double frequencyError = 0.0, shapeError = 0.0;
  for (const Sample& s : samples) {
    frequencyError = std::max(frequencyError, s.frequencyError);
    shapeError = std::max(shapeError, s.shapeError);
    tets.push_back(static_cast<double>(s.tets));
    solves.push_back(s.solves);
    dof.push_back(s.dof);
    morph.push_back(s.morphMs);
    modes.push_back(s.modesMs);
    total.push_back(s.morphMs + s.modesMs);
  }
  std::printf("| %s | %zu | %.0f | %.0f | %.1f | %.1f | %.0f | %.1f | %.1f | %.1f |", name.c_str(),
              samples.size(), core::percentile(tets, 0.5), core::percentile(dof, 0.5),
              core::percentile(morph, 0.5), core::percentile(modes, 0.5), core::percentile(solves, 0.5),
              std::accumulate(solves.begin(), solves.end(), 0.0) / static_cast<double>(solves.size()),
              core::percentile(total, 0.5), core::percentile(total, 0.9));
  if (check) std::printf(" %.1e | %.1e |", frequencyError, shapeError);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s DB [--every K] [--seed S]\n", argv[0]);
    return 2;
  }
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
  std::size_t every = 20;
  std::uint64_t seed = 1;
  for (int i = 2; i + 1 < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--every") every = static_cast<std::size_t>(std::max(1, std::atoi(argv[++i])));
    if (flag == "--seed") seed = std::strtoull(argv[++i], nullptr, 10);
  }
  bool check = false;
  for (int i = 2; i < argc; ++i)
    check = check || std::string(argv[i]) == "--check";
  auto db = io::Database::open(argv[1]);
  if (!db) {
    std::fprintf(stderr, "%s: %s\n", argv[1], db.error().message.c_str());
    return 1;
  }
  const volume::ModalOptions modal = db->parameters().entry.modal;
  std::mt19937_64 rng(seed);
  std::map<std::string, std::vector<Sample>> byFamily;
  std::vector<Sample> all;
  int failed = 0;
  const std::vector<io::EntryRecord>& entries = db->entries();
  for (std::size_t i = 0; i < entries.size(); i += every) {
    const io::EntryRecord& record = entries[i];
    auto physics = db->physics(record.id);
    if (!physics) {
      std::fprintf(stderr, "%s: %s\n", record.name.c_str(), physics.error().message.c_str());
      ++failed;
      continue;
    }
    core::TriangleMesh target = core::boundarySurface((*physics)->tetMesh);
    const core::Mat3 stretch = randomStretch(rng);
    for (core::Vec3& v : target.vertices)
      v = stretch * v;
    // correctGeometry's two halves, so that --check can compute the same modes again.
    auto morphed = volume::morphEntry(**physics, target);
    auto corrected = morphed
                         ? volume::correctMorphed(**physics, check ? *morphed : std::move(*morphed), modal)
                         : Result<volume::CorrectedEntry>(morphed.error());
    if (!corrected) {
      std::fprintf(stderr, "%s: %s\n", record.name.c_str(), corrected.error().message.c_str());
      ++failed;
      continue;
    }
    const volume::CorrectionReport& report = corrected->report;
    Sample s;
    s.tets = (*physics)->tetMesh.tetCount();
    s.dof = modal.order == volume::ElementOrder::kQuadratic
                ? 3.0 * static_cast<double>(volume::makeQuadratic((*physics)->tetMesh).nodeCount())
                : 3.0 * static_cast<double>((*physics)->tetMesh.nodeCount());
    s.morphMs = 1e3 * report.morphSeconds;
    s.modesMs = 1e3 * report.modesSeconds;
    s.solves = report.solves;
    if (check) {
      // The modes the correction kept: with the missing mass spread as density where its lumped mass made
      // a mode of one node (CorrectionReport::massSpread).
      if (report.massSpread) morphed->pointMasses.clear();
      auto reference = volume::computeModes(morphed->tetMesh, volume::morphedModalOptions(*morphed, modal));
      if (!reference) {
        std::fprintf(stderr, "%s: %s\n", record.name.c_str(), reference.error().message.c_str());
        ++failed;
        continue;
      }
      std::tie(s.frequencyError, s.shapeError) = modeDifference(corrected->physics.modes, *reference);
    }
    byFamily[volume::toString(record.family)].push_back(s);
    all.push_back(s);
  }
  std::printf("%s: every %zu-th of %zu entries, %s tets, %d modes; %d failed\n\n", argv[1], every,
              entries.size(), volume::toString(modal.order), modal.modes, failed);
  std::printf(
      "| family | entries | median tets | median dof | morph p50 (ms) | modes p50 | solves p50 | "
      "solves mean | correction p50 | correction p90 "
      "|%s\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|%s\n",
      check ? " frequencies, most off | shapes, most off (1 − MAC) |" : "", check ? "---:|---:|" : "");
  for (const auto& [family, samples] : byFamily)
    printRow(family, samples, check);
  printRow("**all**", all, check);
  return failed == 0 ? 0 : 1;
}
