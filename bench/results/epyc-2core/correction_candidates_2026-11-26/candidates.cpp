// Experiment: correct each of the k best matches; which selection rule picks the best corrected answer?
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <shapedb/core/error_model.h>
#include <shapedb/core/link.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/correction.h>
using namespace shapedb;
int main(int argc, char** argv) {
  auto db = io::Database::open(argv[1]);
  if (!db) {
    std::fprintf(stderr, "%s\n", db.error().message.c_str());
    return 1;
  }
  const int k = std::atoi(argv[2]);
  std::printf(
      "shape,rank,entry,family,distance,mean_dev,max_dev,moment_err,desc_dist,nearest_f1,morph_target,mean_"
      "move,max_move,worst_q,projected,volume_scale,outside,corrected_f1,morph_ms,modes_ms,predicted\n");
  for (int i = 3; i < argc; ++i) {
    auto m = io::loadMesh(argv[i]);
    if (!m) {
      std::fprintf(stderr, "%s: %s\n", argv[i], m.error().message.c_str());
      continue;
    }
    io::QueryOptions q;
    q.search.k = k;
    q.fidelity = true;
    q.adapt = true;
    q.link = false;
    auto r = db->query(m->mesh, q);
    if (!r) {
      std::fprintf(stderr, "%s: %s\n", argv[i], r.error().message.c_str());
      continue;
    }
    const std::string name = std::filesystem::path(argv[i]).stem().string();
    for (std::size_t j = 0; j < r->matches.size(); ++j) {
      const io::MatchReport& mr = r->matches[j];
      auto p = db->physics(mr.match.entry);
      if (!p) continue;
      const core::Placement placement = core::placementOf(r->normalization, mr.match.orientation);
      auto nearest = core::adapt(**p, r->normalization, r->massProperties, mr.match.orientation, q.material,
                                 db->parameters().entry.damping);
      double nf1 = nearest ? nearest->frequenciesHz()[0] : NAN;
      core::TriangleMesh target = m->mesh;
      for (core::Vec3& v : target.vertices)
        v = placement.toEntry(v);
      volume::ModalOptions modal = db->parameters().entry.modal;
      modal.material.poissonRatio = q.material.poissonRatio;
      auto c = volume::correctGeometry(**p, target, modal);
      double cf1 = NAN, outside = NAN, pred = NAN;
      volume::CorrectionReport rep;
      if (c) {
        rep = c->report;
        auto a = core::adapt(c->physics, r->normalization, r->massProperties, mr.match.orientation,
                             q.material, db->parameters().entry.damping);
        if (a) {
          cf1 = a->frequenciesHz()[0];
          core::TetLocator loc(c->physics.tetMesh);
          auto link = core::linkSurface(loc, a->placement, m->mesh.vertices);
          outside = double(link.outsideCount) / double(m->mesh.vertices.size());
          core::ErrorEvidence ev;
          ev.meanDeviation = mr.fidelity->meanDeviation;
          ev.maxDeviation = mr.fidelity->maxDeviation;
          ev.maxMomentError = mr.fidelity->maxMomentError;
          ev.descriptorDistance = mr.fidelity->descriptorDistance;
          ev.outsideShare = outside;
          ev.morphTargetDistance = rep.morph.meanTargetDistance;
          pred = core::predictFrequencyError(ev);
        }
      }
      std::printf("%s,%zu,%s,%s,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g,%g\n", name.c_str(), j,
                  mr.entry->name.c_str(), std::string(volume::toString(mr.entry->family)).c_str(),
                  mr.match.distance, mr.fidelity->meanDeviation, mr.fidelity->maxDeviation,
                  mr.fidelity->maxMomentError, mr.fidelity->descriptorDistance, nf1,
                  rep.morph.meanTargetDistance, rep.morph.meanBoundaryMove, rep.morph.maxBoundaryMove,
                  rep.morph.worstQuality, rep.morph.projected, rep.volumeScale, outside, cf1,
                  rep.morphSeconds * 1e3, rep.modesSeconds * 1e3, pred);
      std::fflush(stdout);
    }
  }
}
