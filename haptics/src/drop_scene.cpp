#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <system_error>

#include <shapedb/core/primitives.h>
#include <shapedb/core/triangle_mesh.h>
#include <shapedb/haptics/drop_scene.h>
#include <shapedb/io/render.h>

namespace shapedb::haptics {
namespace {

/// The surfaces moved by each body's pose, on `stage`; the renderer centres on the bounding box, so a
/// stage that outlasts every pose keeps the framing fixed.
Status saveFrame(const std::vector<const core::TriangleMesh*>& surfaces, const std::vector<core::Mat4>& poses,
                 const core::TriangleMesh& stage, const std::filesystem::path& path) {
  std::vector<core::TriangleMesh> moved;
  moved.reserve(surfaces.size());
  for (std::size_t i = 0; i < surfaces.size(); ++i)
    moved.push_back(core::transformed(*surfaces[i], poses[i]));
  io::Panel panel;
  panel.meshes.push_back(&stage);
  panel.colors.push_back({200, 200, 190});
  for (std::size_t i = 0; i < moved.size(); ++i) {
    panel.meshes.push_back(&moved[i]);
    panel.colors.push_back({static_cast<std::uint8_t>(90 + (i * 67) % 150),
                            static_cast<std::uint8_t>(80 + (i * 41) % 120),
                            static_cast<std::uint8_t>(200 - (i * 29) % 120)});
  }
  // Looking along +y, a little from above: right = x, up ≈ z.
  const double tilt = 0.35;
  core::Mat3 view;
  view.row(0) = core::Vec3(1, 0, 0);
  view.row(1) = core::Vec3(0, std::sin(tilt), std::cos(tilt));
  view.row(2) = core::Vec3(0, -std::cos(tilt), std::sin(tilt));
  const io::Panel panels[] = {panel};
  return io::savePng(io::renderPanels(panels, view, 480), path);
}

/// A floor under the surfaces' footprint and a backdrop behind them as high as the start.
core::TriangleMesh makeStage(const std::vector<const core::TriangleMesh*>& surfaces, double height) {
  core::Vec3 lo = core::Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const core::TriangleMesh* surface : surfaces) {
    const core::Bounds box = core::computeBounds(*surface);
    lo = lo.cwiseMin(box.min);
    hi = hi.cwiseMax(box.max);
  }
  const core::Vec3 size = hi - lo;
  const double margin = 0.6 * std::max(size.x(), size.y());
  const core::Vec3 middle = 0.5 * (lo + hi);
  core::TriangleMesh stage = core::makeBox({size.x() + 2 * margin, size.y() + 2 * margin, 0.002});
  for (core::Vec3& p : stage.vertices)
    p += core::Vec3(middle.x(), middle.y(), -0.001);
  core::TriangleMesh backdrop = core::makeBox({size.x() + 2 * margin, 0.002, height + size.z() + margin});
  for (core::Vec3& p : backdrop.vertices)
    p += core::Vec3(middle.x(), hi.y() + margin, 0.5 * (height + size.z() + margin));
  core::append(stage, backdrop);
  return stage;
}

}  // namespace

Result<DropSceneReport> dropOnFloor(const io::Database& database, const DropScene& scene,
                                    const DropSceneOptions& options) {
  if (scene.names.size() != scene.meshes.size())
    return Error{ErrorCode::kInvalidArgument, "a drop scene needs one name per mesh"};
  // Each body's mass properties and compound from its best match, adapted to its size and material.
  io::QueryOptions query;
  query.material = options.material;
  query.link = false;
  query.fidelity = false;
  DropSceneReport out;
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    Result<io::QueryResult> r = database.query(scene.meshes[i], query);
    if (!r || !r->physics) {
      out.skipped.push_back(
          {scene.names[i], r ? Error{ErrorCode::kInvalidArgument, "no physical data"} : r.error()});
      continue;
    }
    out.bodies.push_back({r->physics->massProperties, r->physics->collision});
    out.source.push_back(i);
  }
  if (out.bodies.empty()) {
    if (out.skipped.empty()) return Error{ErrorCode::kInvalidArgument, "the drop scene has no meshes"};
    std::string message = "no mesh could be given physical data";
    for (const SkippedMesh& s : out.skipped)
      message += "\n" + s.name + ": " + s.error.message;
    return Error{out.skipped.front().error.code, message};
  }

  // Everything raised together so that its lowest collision point is at `height`.
  double lowest = std::numeric_limits<double>::infinity();
  for (const RigidBody& b : out.bodies)
    for (const core::CollisionShape& s : b.collision.shapes)
      lowest = std::min(lowest, lowestPoint(s));
  out.options = options.drop;
  out.options.lift = options.height - lowest;
  Result<DropReport> report = simulateDrop(out.bodies, out.options);
  if (!report) return report.error();
  out.report = std::move(report).value();

  for (std::size_t b = 0; b < out.bodies.size(); ++b) {
    out.deepest = std::min(out.deepest, out.report.bodies[b].lowestPoint);
    out.deepestAtEnd = std::min(out.deepestAtEnd, out.report.bodies[b].finalLowestPoint);
    out.lastRest = std::max(out.lastRest, out.report.bodies[b].restTime);
    out.totalMass += out.bodies[b].massProperties.mass;
  }
  out.energyStart = out.report.kineticEnergy.front() + out.report.potentialEnergy.front();
  out.energyEnd = out.report.kineticEnergy.back() + out.report.potentialEnergy.back();
  return out;
}

Status saveDropFrames(const DropScene& scene, const DropSceneReport& dropped, double height,
                      const std::filesystem::path& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) return Error{ErrorCode::kIo, directory.string() + ": " + ec.message()};
  std::vector<const core::TriangleMesh*> surfaces;
  for (std::size_t i : dropped.source)
    surfaces.push_back(&scene.meshes.at(i));
  const core::TriangleMesh stage = makeStage(surfaces, height);
  for (std::size_t f = 0; f < dropped.report.frames.size(); ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame-%04zu.png", f);
    if (Status st = saveFrame(surfaces, dropped.report.frames[f], stage, directory / name); !st) return st;
  }
  return Ok{};
}

}  // namespace shapedb::haptics
