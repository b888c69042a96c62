// Fits the predicted-error model (core/error_model.h) on `shapedb bench` results and reports its quality
// on results it was not fitted on.
//
//   error_model_fit --fit A/evaluation.csv B/evaluation.csv --test C/evaluation.csv [--ridge L] [--use 1,2,6]
//
// For the nearest entry's answer (method centroid-voxel) and the corrected one (centroid-voxel-corrected):
// ridge least squares of ln(|first-frequency error| + 0.005) on core::errorFeatures over the --fit rows,
// then, on the --fit and on each --test file: Spearman's ρ between predicted and measured |error|, the
// median |ln(predicted / measured)| (how far off the estimate is, as a factor), and at a 10 % threshold
// the share of the answers over it that the estimate flags (recall) and of those flagged that are over it
// (precision). Prints the weights as C++ for core/src/error_model.cpp.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include <shapedb/core/error_model.h>
#include <shapedb/core/statistics.h>

namespace {

using shapedb::core::ErrorEvidence;
using shapedb::core::ErrorFeatures;
using shapedb::core::kErrorFeatures;

constexpr double kTargetFloor = 0.005;  // errors under half a per cent are all "right"
constexpr double kThreshold = 0.10;

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

struct Sample {
  ErrorFeatures features{};
  double error = 0.0;  ///< |first-frequency error|
};

double number(const std::string& s) {
  if (s.empty()) return std::nan("");
  try {
    return std::stod(s);
  } catch (...) {
    return std::nan("");
  }
}

/// The rows of `method` with a measured error and every piece of evidence.
std::vector<Sample> readSamples(const std::string& path, const std::string& method, bool* ok) {
  std::ifstream in(path);
  std::vector<Sample> out;
  std::string line;
  if (!in || !std::getline(in, line)) {
    std::fprintf(stderr, "error_model_fit: %s: cannot read\n", path.c_str());
    *ok = false;
    return out;
  }
  std::map<std::string, std::size_t> column;
  const std::vector<std::string> header = splitCsvLine(line);
  for (std::size_t i = 0; i < header.size(); ++i)
    column[header[i]] = i;
  for (const char* name : {"method", "f1_error", "mean_deviation", "max_deviation", "max_moment_error",
                           "descriptor_distance", "outside_share", "morph_target_distance", "status"})
    if (!column.count(name)) {
      std::fprintf(stderr, "error_model_fit: %s: no column %s (an older bench?)\n", path.c_str(), name);
      *ok = false;
      return out;
    }
  while (std::getline(in, line)) {
    const std::vector<std::string> f = splitCsvLine(line);
    if (f.size() != header.size() || f[column["method"]] != method || f[column["status"]] != "ok") continue;
    ErrorEvidence e;
    e.meanDeviation = number(f[column["mean_deviation"]]);
    e.maxDeviation = number(f[column["max_deviation"]]);
    e.maxMomentError = number(f[column["max_moment_error"]]);
    e.descriptorDistance = number(f[column["descriptor_distance"]]);
    e.outsideShare = number(f[column["outside_share"]]);
    const double morph = number(f[column["morph_target_distance"]]);
    if (std::isfinite(morph)) e.morphTargetDistance = morph;
    // Benches before the mass the morph misses was lumped have no mass_scale: the feature is then 0.
    const double mass = column.count("mass_scale") ? number(f[column["mass_scale"]]) : std::nan("");
    if (std::isfinite(mass)) e.massScale = mass;
    // Nor before the morphed tets outside the shape were measured: stray_share.
    const double stray = column.count("stray_share") ? number(f[column["stray_share"]]) : std::nan("");
    if (std::isfinite(stray)) e.strayShare = stray;
    Sample s;
    s.features = shapedb::core::errorFeatures(e);
    s.error = std::abs(number(f[column["f1_error"]]));
    bool finite = std::isfinite(s.error);
    for (double x : s.features)
      finite = finite && std::isfinite(x);
    if (finite) out.push_back(s);
  }
  return out;
}

/// Features left out of the model (--use): their columns zeroed, so their weights come out 0.
std::array<bool, kErrorFeatures> gUsed = [] {
  std::array<bool, kErrorFeatures> all{};
  all.fill(true);
  return all;
}();

ErrorFeatures fit(const std::vector<Sample>& samples, double ridge) {
  Eigen::MatrixXd a(static_cast<Eigen::Index>(samples.size()), kErrorFeatures);
  Eigen::VectorXd y(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    for (int j = 0; j < kErrorFeatures; ++j)
      a(static_cast<Eigen::Index>(i), j) =
          gUsed[static_cast<std::size_t>(j)] ? samples[i].features[static_cast<std::size_t>(j)] : 0.0;
    y[static_cast<Eigen::Index>(i)] = std::log(samples[i].error + kTargetFloor);
  }
  Eigen::MatrixXd normal = a.transpose() * a;
  for (int j = 1; j < kErrorFeatures; ++j)  // the intercept is not shrunk
    normal(j, j) += ridge * static_cast<double>(samples.size());
  const Eigen::VectorXd w = normal.ldlt().solve(a.transpose() * y);
  ErrorFeatures out{};
  for (int j = 0; j < kErrorFeatures; ++j)
    out[static_cast<std::size_t>(j)] = w[j];
  return out;
}

void report(const char* label, const std::vector<Sample>& samples, const ErrorFeatures& w) {
  std::vector<double> predicted, measured, factor;
  std::size_t over = 0, flagged = 0, both = 0;
  for (const Sample& s : samples) {
    double z = 0.0;
    for (int j = 0; j < kErrorFeatures; ++j)
      z += w[static_cast<std::size_t>(j)] * s.features[static_cast<std::size_t>(j)];
    const double p = std::exp(z);
    predicted.push_back(p);
    measured.push_back(s.error);
    factor.push_back(std::abs(std::log((p + kTargetFloor) / (s.error + kTargetFloor))));
    over += s.error > kThreshold ? 1 : 0;
    flagged += p > kThreshold ? 1 : 0;
    both += s.error > kThreshold && p > kThreshold ? 1 : 0;
  }
  std::printf(
      "  %-40s n %4zu  spearman %6.3f  median |ln(pred/meas)| %5.2f  >10%%: %zu, flagged %zu, "
      "recall %.2f precision %.2f\n",
      label, samples.size(), shapedb::core::spearman(predicted, measured), shapedb::core::median(factor),
      over, flagged, over ? static_cast<double>(both) / static_cast<double>(over) : std::nan(""),
      flagged ? static_cast<double>(both) / static_cast<double>(flagged) : std::nan(""));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> fitFiles, testFiles;
  double ridge = 1e-3;
  std::vector<std::string>* into = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--fit")
      into = &fitFiles;
    else if (a == "--test")
      into = &testFiles;
    else if (a == "--ridge" && i + 1 < argc)
      ridge = std::stod(argv[++i]);
    else if (a == "--use" && i + 1 < argc) {
      // Comma-separated feature indices (core::errorFeatures' order; the intercept, 0, is always used).
      gUsed.fill(false);
      gUsed[0] = true;
      std::stringstream list(argv[++i]);
      for (std::string item; std::getline(list, item, ',');)
        gUsed[static_cast<std::size_t>(std::clamp(std::stoi(item), 0, kErrorFeatures - 1))] = true;
    } else if (into)
      into->push_back(a);
    else {
      std::fprintf(stderr, "usage: error_model_fit --fit CSV... [--test CSV...] [--ridge L]\n");
      return 2;
    }
  }
  if (fitFiles.empty()) {
    std::fprintf(stderr, "usage: error_model_fit --fit CSV... [--test CSV...] [--ridge L]\n");
    return 2;
  }
  bool ok = true;
  for (const char* method : {"centroid-voxel", "centroid-voxel-corrected"}) {
    std::vector<Sample> fitSet;
    for (const std::string& f : fitFiles) {
      const std::vector<Sample> s = readSamples(f, method, &ok);
      fitSet.insert(fitSet.end(), s.begin(), s.end());
    }
    if (!ok) return 1;
    const ErrorFeatures w = fit(fitSet, ridge);
    std::printf("%s (ridge %g):\n  weights {", method, ridge);
    for (int j = 0; j < kErrorFeatures; ++j)
      std::printf("%s%.6g", j ? ", " : "", w[static_cast<std::size_t>(j)]);
    std::printf("}\n");
    report("fit set", fitSet, w);
    std::vector<Sample> heldOut;
    for (const std::string& f : testFiles) {
      const std::vector<Sample> s = readSamples(f, method, &ok);
      if (!ok) return 1;
      report(("held out: " + f).c_str(), s, w);
      heldOut.insert(heldOut.end(), s.begin(), s.end());
    }
    if (testFiles.size() > 1) report("held out, all together", heldOut, w);
  }
  return 0;
}
