// Where does the corrected first-frequency bias on fracture fragments come from?
//   morph_bias DB MESH [fragment indices...]
// Breaks MESH as the bench does (50 pieces, seed 1, 800 triangles), then for each chosen fragment:
//   truth   : computeEntry at the database's entry options with the TetGen volume bound /2 (quadratic)
//   entryres: computeEntry at the database's own entry options (variant 8)
//   variants 1-6: query with correct = true and MorphOptions changed
//   refined8: the default correction's morphed tets (query frame) split 1:8, quadratic modes (variant 7)
//   morphed1: the same tets unsplit, quadratic modes (consistency check against variant 1)
// One CSV line per fragment and variant on stdout.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <vector>

#include <shapedb/core/adapt.h>
#include <shapedb/core/mass_properties.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/entry.h>
#include <shapedb/volume/fracture.h>
#include <shapedb/volume/modal.h>

using namespace shapedb;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Every tet split into 8 (edge midpoints; the octahedron cut along its m02–m13 diagonal).
core::TetMesh splitEight(const core::TetMesh& in) {
  core::TetMesh out;
  out.nodes = in.nodes;
  std::unordered_map<std::uint64_t, std::uint32_t> mid;
  const std::uint64_t n = in.nodes.size();
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    const std::uint64_t key = a * n + b;
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.push_back(0.5 * (in.nodes[a] + in.nodes[b]));
    mid.emplace(key, id);
    return id;
  };
  for (const core::TetMesh::Tet& t : in.tets) {
    const std::uint32_t v0 = t[0], v1 = t[1], v2 = t[2], v3 = t[3];
    const std::uint32_t m01 = midpoint(v0, v1), m02 = midpoint(v0, v2), m03 = midpoint(v0, v3),
                        m12 = midpoint(v1, v2), m13 = midpoint(v1, v3), m23 = midpoint(v2, v3);
    const std::array<core::TetMesh::Tet, 8> kids{{{v0, m01, m02, m03},
                                                  {m01, v1, m12, m13},
                                                  {m02, m12, v2, m23},
                                                  {m03, m13, m23, v3},
                                                  {m01, m02, m03, m13},
                                                  {m01, m02, m12, m13},
                                                  {m02, m03, m13, m23},
                                                  {m02, m12, m13, m23}}};
    for (core::TetMesh::Tet k : kids) {
      out.tets.push_back(k);
      if (core::tetVolume(out, out.tets.size() - 1) < 0.0) std::swap(out.tets.back()[2], out.tets.back()[3]);
    }
  }
  return out;
}

struct Variant {
  std::string name;
  volume::MorphOptions morph;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s DB MESH [fragment indices...]\n", argv[0]);
    return 2;
  }
  auto db = io::Database::open(argv[1], {.descriptors = {core::DescriptorKind::kCentroidVoxel}});
  if (!db) {
    std::fprintf(stderr, "%s\n", db.error().message.c_str());
    return 1;
  }
  auto loaded = io::loadMesh(argv[2]);
  if (!loaded) {
    std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
    return 1;
  }
  const bool skipRefined = std::getenv("SKIP_REFINED") != nullptr;
  const bool skipEntryRes = std::getenv("SKIP_ENTRYRES") != nullptr;
  auto pieces = volume::fracture(loaded->mesh, {.pieces = 50, .seed = 1, .maxTriangles = 800});
  if (!pieces) {
    std::fprintf(stderr, "fracture: %s\n", pieces.error().message.c_str());
    return 1;
  }
  std::fprintf(stderr, "%zu fragments\n", pieces->fragments.size());
  std::vector<std::size_t> chosen;
  for (int i = 3; i < argc; ++i)
    chosen.push_back(static_cast<std::size_t>(std::atoi(argv[i])));

  const volume::EntryOptions entry = db->parameters().entry;
  const core::Material steel = core::materialPresets()[0];
  volume::EntryOptions truthEntry = volume::withElements(entry, volume::ElementOrder::kQuadratic);
  truthEntry.tetgen.maxVolumeFraction /= 2.0;
  truthEntry.tetgen.timeoutSeconds = 600.0;
  std::fprintf(stderr, "entry tetgen: maxVolumeFraction %.5g, modes %d, nu %.3g, steel nu %.3g\n",
               entry.tetgen.maxVolumeFraction, entry.modal.modes, entry.modal.material.poissonRatio,
               steel.poissonRatio);

  std::vector<Variant> variants;
  variants.push_back({"1-default", {}});
  {
    Variant v{"2-reg8", {}};
    v.morph.registrationRounds = 8;
    variants.push_back(v);
  }
  {
    Variant v{"3-reg0", {}};
    v.morph.registrationRounds = 0;
    variants.push_back(v);
  }
  {
    Variant v{"4-minq0.005", {}};
    v.morph.minQuality = 0.005;
    variants.push_back(v);
  }
  {
    Variant v{"5-incr16", {}};
    v.morph.maxIncrements = 16;
    variants.push_back(v);
  }
  {
    Variant v{"6-noprestretch", {}};
    v.morph.prestretch = false;
    variants.push_back(v);
  }

  if (std::getenv("EXTRA")) {
    variants.clear();
    for (int rounds : {8, 16, 32}) {
      Variant v{"x-reg" + std::to_string(rounds), {}};
      v.morph.registrationRounds = rounds;
      variants.push_back(v);
    }
    variants.front().name = "1-default-reg8";  // feeds the split variant below
  }
  volume::MorphOptions splitMorph;
  if (const char* r = std::getenv("SPLIT_REG")) splitMorph.registrationRounds = std::atoi(r);
  std::printf(
      "fragment,variant,f1_hz,f1_truth_hz,f1_error,match,entry_tets,mean_target_distance,worst_quality,"
      "entry_worst_quality,projected,increments,volume_scale,morphs,morph_s,modes_s,correct_us,seconds\n");
  std::fflush(stdout);
  for (const std::size_t idx : chosen) {
    if (idx >= pieces->fragments.size()) continue;
    const core::TriangleMesh& mesh = pieces->fragments[idx];
    const std::string name = volume::fragmentName(idx);
    auto direct = [&](const volume::EntryOptions& options, double& f1, std::size_t& tets, double& s) {
      const Clock::time_point start = Clock::now();
      auto d = volume::computeEntry(mesh, options);
      s = seconds(start);
      if (!d) {
        std::fprintf(stderr, "%s: direct: %s\n", name.c_str(), d.error().message.c_str());
        return false;
      }
      auto a = core::adapt(d->physics, d->normalization, d->surfaceMassProperties, core::Mat3::Identity(),
                           steel, entry.damping);
      if (!a) return false;
      f1 = a->frequenciesHz()[0];
      tets = d->physics.tetMesh.tetCount();
      return true;
    };
    double truth = 0.0, s = 0.0;
    std::size_t tets = 0;
    if (!direct(truthEntry, truth, tets, s)) continue;
    std::printf("%s,truth,%.6g,%.6g,0,,%zu,,,,,,,,,,,%.3g\n", name.c_str(), truth, truth, tets, s);
    std::fflush(stdout);
    if (!skipEntryRes) {
      double f1 = 0.0;
      if (direct(entry, f1, tets, s))
        std::printf("%s,8-entryres,%.6g,%.6g,%.6g,,%zu,,,,,,,,,,,%.3g\n", name.c_str(), f1, truth,
                    (f1 - truth) / truth, tets, s);
      std::fflush(stdout);
    }
    core::TetMesh defaultMorphed;
    std::shared_ptr<const core::PhysicalData> answeredEntry;
    core::Placement placement;
    for (const Variant& v : variants) {
      io::QueryOptions q;
      q.descriptor = core::DescriptorKind::kCentroidVoxel;
      q.search.k = 1;
      q.correct = true;
      q.correction.morph = v.morph;
      q.material = steel;
      q.fidelity = false;
      const Clock::time_point start = Clock::now();
      auto r = db->query(mesh, q);
      const double qs = seconds(start);
      if (!r || !r->physics) {
        std::fprintf(stderr, "%s %s: query failed: %s\n", name.c_str(), v.name.c_str(),
                     r ? "no physics" : r.error().message.c_str());
        continue;
      }
      const double f1 = r->physics->frequenciesHz()[0];
      std::printf("%s,%s,%.6g,%.6g,%.6g,%s,%zu,", name.c_str(), v.name.c_str(), f1, truth,
                  (f1 - truth) / truth, r->answeredMatch().entry->name.c_str(),
                  r->physics->tetMesh.tetCount());
      if (r->correction) {
        const volume::CorrectionReport& c = *r->correction;
        std::printf("%.5g,%.5g,%.5g,%.5g,%d,%.6g,%d,%.4g,%.4g,%.6g,%.3g\n", c.morph.meanTargetDistance,
                    c.morph.worstQuality, c.morph.entryWorstQuality, c.morph.projected, c.morph.increments,
                    c.volumeScale, c.morphs, c.morphSeconds, c.modesSeconds, r->times.correct, qs);
      } else {
        std::printf(",,,,,,,,,%.6g,%.3g\n", r->times.correct, qs);
        for (const std::string& w : r->physics->warnings)
          std::fprintf(stderr, "  warning: %s\n", w.c_str());
      }
      std::fflush(stdout);
      if (v.name.rfind("1-default", 0) == 0 && r->correction) {
        defaultMorphed = r->physics->tetMesh;
        answeredEntry = r->entryPhysics;
        placement = r->physics->placement;
      }
    }
    if (!defaultMorphed.tets.empty()) {
      volume::ModalOptions modal = entry.modal;
      modal.material = steel;
      modal.modes = 3;
      {
        const Clock::time_point start = Clock::now();
        auto m = volume::computeModes(defaultMorphed, modal);
        if (m)
          std::printf("%s,7a-morphed1,%.6g,%.6g,%.6g,,%zu,,,,,,,,,,,%.3g\n", name.c_str(),
                      m->frequenciesHz()[0], truth, (m->frequenciesHz()[0] - truth) / truth,
                      defaultMorphed.tetCount(), seconds(start));
        else
          std::fprintf(stderr, "%s: morphed modes: %s\n", name.c_str(), m.error().message.c_str());
        std::fflush(stdout);
      }
      if (answeredEntry) {
        // 9: the entry's tets split 1:8 before the morph (four times the boundary nodes to land on the
        // target).
        core::TriangleMesh target = mesh;
        for (core::Vec3& p : target.vertices)
          p = placement.toEntry(p);
        const Clock::time_point start = Clock::now();
        const core::TetMesh fineEntry = splitEight(answeredEntry->tetMesh);
        auto morphed = volume::morphTetMesh(fineEntry, target, splitMorph);
        if (!morphed) {
          std::fprintf(stderr, "%s: split morph: %s\n", name.c_str(), morphed.error().message.c_str());
        } else {
          const double morphS = seconds(start);
          core::TetMesh m = morphed->mesh;
          double scale = 1.0;
          if (auto tm = core::computeMassProperties(target); tm) {
            const core::MassProperties own = core::computeTetMassProperties(m);
            scale = std::cbrt(tm->volume / own.volume);
            for (core::Vec3& p : m.nodes)
              p = own.centerOfMass + scale * (p - own.centerOfMass);
          }
          for (core::Vec3& p : m.nodes)
            p = placement.toQuery(p);
          const Clock::time_point modesStart = Clock::now();
          auto md = volume::computeModes(m, modal);
          const double modesS = seconds(modesStart);
          if (md) {
            const volume::MorphReport& c = morphed->report;
            const double f1 = md->frequenciesHz()[0];
            std::printf(
                "%s,9-splitentry,%.6g,%.6g,%.6g,%s,%zu,%.5g,%.5g,%.5g,%.5g,%d,%.6g,1,%.4g,%.4g,%.6g,%.3g\n",
                name.c_str(), f1, truth, (f1 - truth) / truth, "", m.tetCount(), c.meanTargetDistance,
                c.worstQuality, c.entryWorstQuality, c.projected, c.increments, scale, morphS, modesS,
                1e6 * (morphS + modesS), seconds(start));
          } else {
            std::fprintf(stderr, "%s: split modes: %s\n", name.c_str(), md.error().message.c_str());
          }
          std::fflush(stdout);
        }
      }
      if (!skipRefined) {
        const core::TetMesh fine = splitEight(defaultMorphed);
        const Clock::time_point start = Clock::now();
        auto m = volume::computeModes(fine, modal);
        if (m)
          std::printf("%s,7-refined8,%.6g,%.6g,%.6g,,%zu,,,,,,,,,,,%.3g\n", name.c_str(),
                      m->frequenciesHz()[0], truth, (m->frequenciesHz()[0] - truth) / truth, fine.tetCount(),
                      seconds(start));
        else
          std::fprintf(stderr, "%s: refined modes: %s\n", name.c_str(), m.error().message.c_str());
        std::fflush(stdout);
        if (std::getenv("REFINE_TWICE")) {
          const core::TetMesh finer = splitEight(fine);
          const Clock::time_point start2 = Clock::now();
          auto m2 = volume::computeModes(finer, modal);
          if (m2)
            std::printf("%s,7-refined64,%.6g,%.6g,%.6g,,%zu,,,,,,,,,,,%.3g\n", name.c_str(),
                        m2->frequenciesHz()[0], truth, (m2->frequenciesHz()[0] - truth) / truth,
                        finer.tetCount(), seconds(start2));
          std::fflush(stdout);
        }
      }
    }
  }
  return 0;
}
