// How accurate the database's modes are at its meshing: for a sample of entries of every family, the first
// five non-rigid frequencies at the build's meshing against the same surface meshed about three times finer
// (a third of the tet size: 1/27 of the volume bound and a tighter quality bound), both on the build's
// elements. Prints one row per entry and a table per family (median and worst relative error over the five
// frequencies), with the mean wall time of an entry's tetrahedralization and modes at the build's meshing.
//   build/release/bin/element_accuracy [--per-family N] [--elements linear|quadratic]
//       [--quality Q] [--volume-fraction F] [--family-volume-fraction FAMILY=F]
//       [--wall-fraction W] [--reference-wall-fraction R]
//       [--segments S] [--stacks T] [--union-triangles-per-segment U] [--stone-subdivisions K]
//       [--modes M] [--families LIST] [--csv FILE]
// Defaults: 6 entries per family spread over the default catalog's sweep, the default build's elements and
// TetGen bounds (the families' own volume bounds too, unless --volume-fraction sets one for all; after it,
// --family-volume-fraction gives a family one of its own, measured against the same reference as the
// others), 20 modes (the time a build pays), the default families.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <shapedb/io/store.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/tetrahedralize.h>

namespace {

using namespace shapedb;

struct Row {
  std::string name;
  volume::Family family = volume::Family::kBox;
  std::size_t tets = 0, referenceTets = 0;
  double seconds = 0.0;        ///< tetrahedralize + modes at the build's meshing, wall time
  std::vector<double> errors;  ///< per frequency, relative, signed
  std::string error;
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  int perFamily = 6, modes = 20;
  io::BuildParameters defaults;
  volume::EntryOptions options = defaults.entry;
  std::vector<volume::Family> families(volume::generatedFamilies().begin(),
                                       volume::generatedFamilies().end());
  std::string csvPath;
  double referenceWallFraction = -1.0;  // < 0: a third of the entries'
  volume::ShapeResolution resolution = defaults.resolution;
  // The families meshed with a volume bound of their own, as the build meshes them (none once
  // --volume-fraction sets every family's).
  io::FamilyVolumeFractions volumeFractions = defaults.volumeFractions;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    if (arg == "--per-family" && value) {
      perFamily = std::atoi(argv[++i]);
    } else if (arg == "--elements" && value) {
      auto order = volume::parseElementOrder(argv[++i]);
      if (!order) return std::fprintf(stderr, "unknown elements '%s'\n", argv[i]), 2;
      options = volume::withElements(options, *order);
      volumeFractions = io::entryVolumeFractions(*order);
    } else if (arg == "--quality" && value) {
      options.tetgen.maxRadiusEdgeRatio = std::atof(argv[++i]);
    } else if (arg == "--volume-fraction" && value) {
      options.tetgen.maxVolumeFraction = std::atof(argv[++i]);
      volumeFractions.clear();
    } else if (arg == "--family-volume-fraction" && value) {
      // FAMILY=F: that family's own volume bound, as BuildParameters::volumeFractions gives one.
      const std::string pair = argv[++i];
      const std::size_t at = pair.find('=');
      const auto family = volume::parseFamily(pair.substr(0, at));
      const double fraction = at == std::string::npos ? 0.0 : std::atof(pair.c_str() + at + 1);
      if (!family || !io::validVolumeFraction(fraction))
        return std::fprintf(stderr, "--family-volume-fraction takes FAMILY=F, F in (0, 1]\n"), 2;
      volumeFractions[*family] = fraction;
    } else if (arg == "--wall-fraction" && value) {
      options.tetgen.wallEdgeFraction = std::atof(argv[++i]);
    } else if (arg == "--reference-wall-fraction" && value) {
      referenceWallFraction = std::atof(argv[++i]);
    } else if (arg == "--segments" && value) {
      resolution.segments = std::atoi(argv[++i]);
    } else if (arg == "--stacks" && value) {
      resolution.stacks = std::atoi(argv[++i]);
    } else if (arg == "--union-triangles-per-segment" && value) {
      resolution.unionTrianglesPerSegment = std::atoi(argv[++i]);
    } else if (arg == "--stone-subdivisions" && value) {
      resolution.stoneSubdivisions = std::atoi(argv[++i]);
    } else if (arg == "--modes" && value) {
      modes = std::atoi(argv[++i]);
    } else if (arg == "--families" && value) {
      auto parsed = volume::parseFamilies(argv[++i]);
      if (!parsed) return std::fprintf(stderr, "%s\n", parsed.error().message.c_str()), 2;
      families = *parsed;
    } else if (arg == "--csv" && value) {
      csvPath = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: %s [--per-family N] [--elements linear|quadratic] [--quality Q]\n"
                   "       [--volume-fraction F] [--family-volume-fraction FAMILY=F]\n"
                   "       [--wall-fraction W] [--reference-wall-fraction R]\n"
                   "       [--segments S] [--stacks T] [--union-triangles-per-segment U]\n"
                   "       [--stone-subdivisions K] [--modes M]\n"
                   "       [--families LIST] [--csv FILE]\n",
                   argv[0]);
      return 2;
    }
  }
  options.modal.modes = modes;
  // The reference: a third of the tet size (1/27 of the volume bound, a third of the wall bound), quality
  // bound 1.5 at most. A family with a volume bound of its own is measured against the same reference as
  // the others: its error includes what its coarser bound costs.
  volume::EntryOptions reference = options;
  reference.modal.modes = 5;
  reference.tetgen.maxRadiusEdgeRatio = std::min(1.5, options.tetgen.maxRadiusEdgeRatio);
  reference.tetgen.maxVolumeFraction = options.tetgen.maxVolumeFraction / 27.0;
  reference.tetgen.wallEdgeFraction =
      referenceWallFraction >= 0.0 ? referenceWallFraction : options.tetgen.wallEdgeFraction / 3.0;
  reference.tetgen.timeoutSeconds = 300.0;
  std::printf("elements %s, TetGen %s (wall bound %g) against %s (%g), %d modes\n",
              volume::toString(options.modal.order), volume::tetgenSwitches(options.tetgen, 1.0).c_str(),
              options.tetgen.wallEdgeFraction, volume::tetgenSwitches(reference.tetgen, 1.0).c_str(),
              reference.tetgen.wallEdgeFraction, modes);
  for (const auto& [family, fraction] : volumeFractions)
    std::printf("  %s: tets ≤ %g of the volume\n", volume::toString(family), fraction);

  // Each family's entries are meshed as the build meshes them: these options, with its own volume bound.
  io::BuildParameters meshing;
  meshing.entry = options;
  meshing.volumeFractions = volumeFractions;

  // Samples spread over each family's sweep as far as the default catalog takes it.
  const volume::FamilyMix mix = volume::defaultFamilyMix();
  const auto catalog = volume::buildCatalog(defaults.entries, mix.families, mix.weights);
  std::vector<Row> rows;
  for (volume::Family family : families) {
    const auto perFamilyInCatalog = static_cast<std::size_t>(
        std::ranges::count(catalog, family, [](const volume::ShapeSpec& spec) { return spec.family; }));
    for (int s = 0; s < perFamily; ++s) {
      const auto index = static_cast<std::uint32_t>(perFamilyInCatalog * static_cast<std::size_t>(s) /
                                                    static_cast<std::size_t>(perFamily));
      const volume::ShapeSpec spec = volume::familySpec(family, index);
      Row row;
      row.name = spec.name();
      row.family = family;
      auto surface = volume::makeFamilyShape(spec, resolution);
      if (!surface) {
        row.error = surface.error().message;
        rows.push_back(row);
        continue;
      }
      auto entry = volume::computeEntry(*surface, io::entryOptionsFor(meshing, family));
      auto fine = entry ? volume::computeEntry(*surface, reference) : entry;
      if (!entry || !fine) {
        row.error = (!entry ? entry : fine).error().message;
      } else {
        row.seconds = entry->times.tetrahedralize + entry->times.modes;
        row.tets = entry->physics.tetMesh.tetCount();
        row.referenceTets = fine->physics.tetMesh.tetCount();
        const Eigen::VectorXd& f = entry->physics.modes.eigenvalues;
        const Eigen::VectorXd& r = fine->physics.modes.eigenvalues;
        for (Eigen::Index k = 0; k < std::min<Eigen::Index>(5, r.size()); ++k)
          row.errors.push_back(std::sqrt(f[k] / r[k]) - 1.0);
      }
      std::printf("%-16s tets %6zu ref %7zu  %6.3f s ", row.name.c_str(), row.tets, row.referenceTets,
                  row.seconds);
      for (double e : row.errors)
        std::printf(" %+6.2f%%", 100.0 * e);
      if (!row.error.empty()) std::printf("  FAILED: %s", row.error.c_str());
      std::printf("\n");
      std::fflush(stdout);
      rows.push_back(row);
    }
  }

  std::printf("\n| family | entries | tets (median) | median error | worst error | s per entry (mean) |\n");
  std::printf("|---|---|---|---|---|---|\n");
  std::vector<double> all, seconds;
  double worstAll = 0.0;
  for (volume::Family family : families) {
    std::vector<double> errors, tets, time;
    double worst = 0.0;
    std::size_t n = 0;
    for (const Row& row : rows) {
      if (row.family != family || !row.error.empty()) continue;
      ++n;
      tets.push_back(static_cast<double>(row.tets));
      time.push_back(row.seconds);
      for (double e : row.errors) {
        errors.push_back(std::abs(e));
        worst = std::max(worst, std::abs(e));
      }
    }
    double meanTime = 0.0;
    for (double t : time)
      meanTime += t / static_cast<double>(std::max<std::size_t>(1, time.size()));
    std::printf("| %s | %zu | %.0f | %.2f %% | %.2f %% | %.3f |\n", volume::toString(family), n, median(tets),
                100.0 * median(errors), 100.0 * worst, meanTime);
    all.insert(all.end(), errors.begin(), errors.end());
    seconds.insert(seconds.end(), time.begin(), time.end());
    worstAll = std::max(worstAll, worst);
  }
  double meanAll = 0.0;
  for (double t : seconds)
    meanAll += t / static_cast<double>(std::max<std::size_t>(1, seconds.size()));
  std::printf("| all | %zu | | %.2f %% | %.2f %% | %.3f |\n", seconds.size(), 100.0 * median(all),
              100.0 * worstAll, meanAll);
  std::size_t failed = 0;
  for (const Row& row : rows)
    failed += row.error.empty() ? 0 : 1;
  if (failed) std::printf("%zu entries failed (see FAILED above)\n", failed);

  if (!csvPath.empty()) {
    std::ofstream csv(csvPath);
    csv << "name,family,tets,reference_tets,seconds,error1,error2,error3,error4,error5,failure\n";
    for (const Row& row : rows) {
      csv << row.name << ',' << volume::toString(row.family) << ',' << row.tets << ',' << row.referenceTets
          << ',' << row.seconds;
      for (std::size_t k = 0; k < 5; ++k)
        csv << ',' << (k < row.errors.size() ? std::to_string(row.errors[k]) : "");
      csv << ",\"" << row.error << "\"\n";
    }
  }
  return 0;
}
