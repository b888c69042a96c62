#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

#include <shapedb/core/primitives.h>

#include "family_shapes.h"
#include "random_draws.h"

namespace shapedb::volume::detail {
namespace {

using core::TriangleMesh;
using core::Vec3;
using Vec2 = Eigen::Vector2d;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// Reverses every triangle of a closed surface that encloses a negative volume.
TriangleMesh outward(TriangleMesh mesh) {
  if (core::computeSignedVolume(mesh) < 0.0)
    for (auto& t : mesh.triangles)
      std::swap(t[1], t[2]);
  return mesh;
}

/// Quads between consecutive rings of `ringSize` vertices, rings [first, first + rings), each ring closed
/// around; `wrap` also joins the last ring to the first (a torus).
void stitchRings(TriangleMesh& mesh, std::uint32_t first, std::uint32_t rings, std::uint32_t ringSize,
                 bool wrap) {
  const std::uint32_t spans = wrap ? rings : rings - 1;
  for (std::uint32_t i = 0; i < spans; ++i) {
    const std::uint32_t a = first + i * ringSize, b = first + ((i + 1) % rings) * ringSize;
    for (std::uint32_t j = 0; j < ringSize; ++j) {
      const std::uint32_t k = (j + 1) % ringSize;
      mesh.triangles.push_back({a + j, b + j, b + k});
      mesh.triangles.push_back({a + j, b + k, a + k});
    }
  }
}

/// A fan from a new centre vertex over the ring [first, first + ringSize), closing a tube's end.
void capRing(TriangleMesh& mesh, std::uint32_t first, std::uint32_t ringSize, const Vec3& centre,
             bool reversed) {
  const auto c = static_cast<std::uint32_t>(mesh.vertices.size());
  mesh.vertices.push_back(centre);
  for (std::uint32_t j = 0; j < ringSize; ++j) {
    const std::uint32_t a = first + j, b = first + (j + 1) % ringSize;
    if (reversed)
      mesh.triangles.push_back({c, b, a});
    else
      mesh.triangles.push_back({c, a, b});
  }
}

double cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// Ear clipping of a simple polygon given counter-clockwise: n − 2 triangles of its vertex indices,
/// counter-clockwise. A vertex is an ear when its corner is convex and no other vertex lies in or on the
/// triangle it cuts off. O(n²) per ear, for the dozen vertices of a beam's section.
std::vector<std::array<std::uint32_t, 3>> earClip(const std::vector<Vec2>& polygon) {
  std::vector<std::uint32_t> left(polygon.size());
  for (std::uint32_t i = 0; i < left.size(); ++i)
    left[i] = i;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  while (left.size() > 3) {
    bool clipped = false;
    for (std::size_t i = 0; i < left.size() && !clipped; ++i) {
      const std::uint32_t p = left[(i + left.size() - 1) % left.size()], c = left[i],
                          n = left[(i + 1) % left.size()];
      const Vec2 &a = polygon[p], &b = polygon[c], &d = polygon[n];
      if (cross2(b - a, d - b) <= 1e-12) continue;  // reflex or flat corner
      const bool blocked = std::any_of(left.begin(), left.end(), [&](std::uint32_t q) {
        if (q == p || q == c || q == n) return false;
        const Vec2& x = polygon[q];
        return cross2(b - a, x - a) >= 0.0 && cross2(d - b, x - b) >= 0.0 && cross2(a - d, x - d) >= 0.0;
      });
      if (blocked) continue;
      triangles.push_back({p, c, n});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) break;  // not a simple polygon: never for the sections below
  }
  if (left.size() == 3) triangles.push_back({left[0], left[1], left[2]});
  return triangles;
}

/// The beam sections, counter-clockwise, in [0, 1] × [0, h] with walls t.
std::vector<Vec2> sectionOf(BeamSection section, double t, double h) {
  const double m = 0.5, w = 0.5 * t;  // the web's centre line and half-width
  switch (section) {
    case BeamSection::kL:
      return {{0, 0}, {1, 0}, {1, t}, {t, t}, {t, h}, {0, h}};
    case BeamSection::kT:
      return {{m - w, 0}, {m + w, 0}, {m + w, h - t}, {1, h - t}, {1, h}, {0, h}, {0, h - t}, {m - w, h - t}};
    case BeamSection::kU:
      return {{0, 0}, {1, 0}, {1, h}, {1 - t, h}, {1 - t, t}, {t, t}, {t, h}, {0, h}};
    case BeamSection::kH:
    case BeamSection::kI:
      return {{0, 0}, {1, 0}, {1, t},     {m + w, t},     {m + w, h - t}, {1, h - t},
              {1, h}, {0, h}, {0, h - t}, {m - w, h - t}, {m - w, t},     {0, t}};
  }
  return {};
}

/// The surface of revolution about z of a closed profile in the (r, z) half-plane: a ring of `segments`
/// vertices for every profile point off the axis, one vertex for a point on it (r = 0), and a band of
/// quads or a fan for every profile segment but those along the axis. Outward-wound.
TriangleMesh revolve(const std::vector<Vec2>& profile, int segments) {
  const auto m = static_cast<std::uint32_t>(segments);
  TriangleMesh mesh;
  std::vector<std::uint32_t> first;  // each profile point's first vertex
  for (const Vec2& p : profile) {
    first.push_back(static_cast<std::uint32_t>(mesh.vertices.size()));
    if (p.x() == 0.0) {
      mesh.vertices.emplace_back(0.0, 0.0, p.y());
      continue;
    }
    for (std::uint32_t j = 0; j < m; ++j) {
      const double phi = kTwoPi * j / m;
      mesh.vertices.emplace_back(p.x() * std::cos(phi), p.x() * std::sin(phi), p.y());
    }
  }
  for (std::size_t k = 0; k < profile.size(); ++k) {
    const std::size_t l = (k + 1) % profile.size();
    const bool poleA = profile[k].x() == 0.0, poleB = profile[l].x() == 0.0;
    const std::uint32_t a = first[k], b = first[l];
    for (std::uint32_t j = 0; j < m && !(poleA && poleB); ++j) {
      const std::uint32_t i = (j + 1) % m;
      if (poleA) {
        mesh.triangles.push_back({a, b + j, b + i});
      } else if (poleB) {
        mesh.triangles.push_back({a + j, b, a + i});
      } else {
        mesh.triangles.push_back({a + j, b + j, b + i});
        mesh.triangles.push_back({a + j, b + i, a + i});
      }
    }
  }
  return outward(std::move(mesh));
}

/// A box of half-extents (1, depth, height) with a pocket open at +z, walls and floor `wall` thick.
TriangleMesh openBox(double height, double wall, double depth) {
  TriangleMesh mesh;
  // Corners: outer (±1, ±depth, ±height), inner (±(1 − wall), ±(depth − wall), height or wall − height).
  const auto corner = [&](bool inner, int x, int y, int z) {
    return static_cast<std::uint32_t>((inner ? 8 : 0) + 4 * x + 2 * y + z);
  };
  for (const bool inner : {false, true})
    for (int x = 0; x < 2; ++x)
      for (int y = 0; y < 2; ++y)
        for (int z = 0; z < 2; ++z) {
          const double hx = inner ? 1.0 - wall : 1.0, hy = inner ? depth - wall : depth;
          const double pz = z == 1 ? height : inner ? wall - height : -height;
          mesh.vertices.emplace_back(x ? hx : -hx, y ? hy : -hy, pz);
        }
  // Each quad wound so that its normal is `out` (away from the solid).
  const auto quad = [&](std::array<std::uint32_t, 4> q, const Vec3& out) {
    const Vec3 n =
        (mesh.vertices[q[1]] - mesh.vertices[q[0]]).cross(mesh.vertices[q[2]] - mesh.vertices[q[0]]);
    if (n.dot(out) < 0.0) std::swap(q[1], q[3]);
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  };
  for (const bool inner : {false, true}) {
    const double s = inner ? -1.0 : 1.0;  // the pocket's walls face into it
    for (int x = 0; x < 2; ++x)
      quad({corner(inner, x, 0, 0), corner(inner, x, 1, 0), corner(inner, x, 1, 1), corner(inner, x, 0, 1)},
           s * Vec3(x ? 1 : -1, 0, 0));
    for (int y = 0; y < 2; ++y)
      quad({corner(inner, 0, y, 0), corner(inner, 1, y, 0), corner(inner, 1, y, 1), corner(inner, 0, y, 1)},
           s * Vec3(0, y ? 1 : -1, 0));
    quad({corner(inner, 0, 0, 0), corner(inner, 1, 0, 0), corner(inner, 1, 1, 0), corner(inner, 0, 1, 0)},
         Vec3(0, 0, inner ? 1 : -1));
  }
  // The rim: four trapezoids between the outer and the inner top edges.
  for (int x = 0; x < 2; ++x)
    quad({corner(false, x, 0, 1), corner(false, x, 1, 1), corner(true, x, 1, 1), corner(true, x, 0, 1)},
         Vec3::UnitZ());
  for (int y = 0; y < 2; ++y)
    quad({corner(false, 0, y, 1), corner(false, 1, y, 1), corner(true, 1, y, 1), corner(true, 0, y, 1)},
         Vec3::UnitZ());
  return mesh;
}

/// Appends the planar quad q (a cycle) as two triangles, wound so that its normal points along `out`.
void addQuad(TriangleMesh& mesh, std::array<std::uint32_t, 4> q, const Vec3& out) {
  const Vec3 n = (mesh.vertices[q[1]] - mesh.vertices[q[0]]).cross(mesh.vertices[q[2]] - mesh.vertices[q[0]]);
  if (n.dot(out) < 0.0) std::swap(q[1], q[3]);
  mesh.triangles.push_back({q[0], q[1], q[2]});
  mesh.triangles.push_back({q[0], q[2], q[3]});
}

void addTriangle(TriangleMesh& mesh, std::array<std::uint32_t, 3> t, const Vec3& out) {
  const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]]).cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
  if (n.dot(out) < 0.0) std::swap(t[1], t[2]);
  mesh.triangles.push_back(t);
}

}  // namespace

TriangleMesh makeHoledShape(double a, double b, int holes, double fill, int segments) {
  const int cols = std::max(1, static_cast<int>(std::lround(std::sqrt(holes / a))));
  const int rows = (holes + cols - 1) / cols;
  const int k = std::max(2, segments / 4);  // lattice points along a cell's side: holes are 4k-gons
  const double cw = 2.0 / cols, ch = 2.0 * a / rows;
  const double r = 0.5 * fill * std::min(cw, ch);
  TriangleMesh mesh;
  // The faces' vertices on the cells' edges: a lattice k to a cell, shared by the cells that meet there.
  std::map<std::array<int, 3>, std::uint32_t> lattice;  // (i, j, top) → vertex
  const auto at = [&](int i, int j, int top) {
    const auto [it, added] =
        lattice.try_emplace({i, j, top}, static_cast<std::uint32_t>(mesh.vertices.size()));
    if (added) mesh.vertices.emplace_back(-1.0 + i * cw / k, -a + j * ch / k, top ? b : -b);
    return it->second;
  };
  const auto cycle = [&](int i0, int j0, int size) {  // a lattice square's boundary, counter-clockwise
    std::vector<std::array<int, 2>> points;
    for (int s = 0; s < size; ++s)
      points.push_back({i0 + s, j0});
    for (int s = 0; s < size; ++s)
      points.push_back({i0 + size, j0 + s});
    for (int s = 0; s < size; ++s)
      points.push_back({i0 + size - s, j0 + size});
    for (int s = 0; s < size; ++s)
      points.push_back({i0, j0 + size - s});
    return points;
  };
  for (int cy = 0; cy < rows; ++cy)
    for (int cx = 0; cx < cols; ++cx) {
      const std::vector<std::array<int, 2>> boundary = cycle(cx * k, cy * k, k);
      const auto n = static_cast<std::uint32_t>(boundary.size());
      const Vec3 centre(-1.0 + (cx + 0.5) * cw, -a + (cy + 0.5) * ch, 0.0);
      if (cy * cols + cx >= holes) {  // solid: a fan from the cell's centre, top and bottom
        for (const int top : {0, 1}) {
          const auto c = static_cast<std::uint32_t>(mesh.vertices.size());
          mesh.vertices.push_back(centre + Vec3(0, 0, top ? b : -b));
          for (std::uint32_t s = 0; s < n; ++s) {
            const auto& p = boundary[s];
            const auto& q = boundary[(s + 1) % n];
            addTriangle(mesh, {c, at(p[0], p[1], top), at(q[0], q[1], top)}, Vec3(0, 0, top ? 1 : -1));
          }
        }
        continue;
      }
      // A hole: its rim points on the rays from the centre to the cell's lattice points (made first, so
      // that each rim's vertices are consecutive).
      for (const int top : {0, 1})
        for (const auto& p : boundary)
          at(p[0], p[1], top);
      std::array<std::uint32_t, 2> rim{};
      for (const int top : {0, 1}) {
        rim[top] = static_cast<std::uint32_t>(mesh.vertices.size());
        for (const auto& p : boundary) {
          const Vec3 ray =
              (mesh.vertices[at(p[0], p[1], top)] - centre).cwiseProduct(Vec3(1, 1, 0)).normalized();
          mesh.vertices.push_back(centre + r * ray + Vec3(0, 0, top ? b : -b));
        }
      }
      for (std::uint32_t s = 0; s < n; ++s) {
        const std::uint32_t t = (s + 1) % n;
        const auto& p = boundary[s];
        const auto& q = boundary[t];
        for (const int top : {0, 1})
          addQuad(mesh, {at(p[0], p[1], top), at(q[0], q[1], top), rim[top] + t, rim[top] + s},
                  Vec3(0, 0, top ? 1 : -1));
        const Vec3 mid = 0.5 * (mesh.vertices[rim[0] + s] + mesh.vertices[rim[0] + t]);
        addQuad(mesh, {rim[0] + s, rim[0] + t, rim[1] + t, rim[1] + s},
                (centre - mid).cwiseProduct(Vec3(1, 1, 0)));
      }
    }
  // The plate's own rim: the lattice around the whole grid, top to bottom.
  const int wide = cols * k, high = rows * k;
  std::vector<std::array<int, 2>> outline;
  for (int i = 0; i < wide; ++i)
    outline.push_back({i, 0});
  for (int j = 0; j < high; ++j)
    outline.push_back({wide, j});
  for (int i = wide; i > 0; --i)
    outline.push_back({i, high});
  for (int j = high; j > 0; --j)
    outline.push_back({0, j});
  for (std::size_t s = 0; s < outline.size(); ++s) {
    const auto& p = outline[s];
    const auto& q = outline[(s + 1) % outline.size()];
    const Vec3 mid = 0.5 * (mesh.vertices[at(p[0], p[1], 1)] + mesh.vertices[at(q[0], q[1], 1)]);
    addQuad(mesh, {at(p[0], p[1], 1), at(q[0], q[1], 1), at(q[0], q[1], 0), at(p[0], p[1], 0)},
            Vec3(mid.x(), mid.y() / a, 0.0));
  }
  return mesh;
}

TriangleMesh makeShellShape(ShellKind kind, double height, double wall, double depth, int segments) {
  const double h = height, w = wall, inner = 1.0 - wall;
  switch (kind) {
    case ShellKind::kCup:
      return revolve({{0, -h}, {1, -h}, {1, h}, {inner, h}, {inner, w - h}, {0, w - h}}, 2 * segments);
    case ShellKind::kTube:
      return revolve({{inner, -h}, {1, -h}, {1, h}, {inner, h}}, 2 * segments);
    case ShellKind::kBowl: {
      // Half an ellipsoid shell, the rim at z = 0: the outer arc from the bottom pole up, the inner down.
      std::vector<Vec2> profile;
      const int steps = std::max(2, segments / 2);
      for (int s = 0; s <= steps; ++s) {
        const double t = 0.5 * std::numbers::pi * s / steps;
        profile.emplace_back(std::sin(t), -h * std::cos(t));
      }
      for (int s = steps; s >= 0; --s) {
        const double t = 0.5 * std::numbers::pi * s / steps;
        profile.emplace_back(inner * std::sin(t), -(h - w) * std::cos(t));
      }
      return revolve(profile, 2 * segments);
    }
    case ShellKind::kOpenBox:
      return openBox(h, w, depth);
  }
  return {};
}

/// Rings of sections along a centre line this many section edges apart: triangles TetGen keeps without
/// refining the surface around them.
constexpr double kStationsApart = 2.5;

TriangleMesh makeRingShape(double tube, double flatness, int segments) {
  const auto section = static_cast<std::uint32_t>(std::max(6, 3 * segments / 4));
  const double edge = kTwoPi * tube * (1.0 + flatness) / 2.0 / section;
  // Around the axis a multiple of four: the ring's symmetry is then one the normalization recognizes,
  // and a copy of it turned in its plane finds the same canonical frame.
  const auto around = 4 * static_cast<std::uint32_t>(std::ceil(
                              std::clamp(kTwoPi / (kStationsApart * edge), 12.0, 4.0 * segments) / 4));
  TriangleMesh mesh;
  for (std::uint32_t i = 0; i < around; ++i) {
    const double phi = kTwoPi * i / around;
    for (std::uint32_t j = 0; j < section; ++j) {
      const double theta = kTwoPi * j / section;
      const double rho = 1.0 + tube * std::cos(theta);
      mesh.vertices.emplace_back(rho * std::cos(phi), rho * std::sin(phi), tube * flatness * std::sin(theta));
    }
  }
  stitchRings(mesh, 0, around, section, /*wrap=*/true);
  return outward(std::move(mesh));
}

TriangleMesh makeRodShape(double angle, double radius, double shank, int segments) {
  // The centre line: the shank up the line x = 1 to (1, 0, 0), then the arc about z; at every station
  // the section's plane holds the radial direction n and z.
  struct Station {
    Vec3 centre, normal;
  };
  const auto section = static_cast<std::uint32_t>(std::max(6, segments / 2));
  const double spacing =
      std::clamp(kStationsApart * kTwoPi * radius / section, std::numbers::pi / 32.0, std::numbers::pi / 8.0);
  std::vector<Station> stations;
  if (shank > 0.0) {
    const int steps = std::max(1, static_cast<int>(std::ceil(shank / spacing)));
    for (int s = 0; s < steps; ++s)
      stations.push_back({Vec3(1.0, -shank * (1.0 - static_cast<double>(s) / steps), 0.0), Vec3::UnitX()});
  }
  const int arcSteps = std::max(2, static_cast<int>(std::ceil(angle / spacing)));
  for (int s = 0; s <= arcSteps; ++s) {
    const double a = angle * s / arcSteps;
    const Vec3 radial(std::cos(a), std::sin(a), 0.0);
    stations.push_back({radial, radial});
  }
  TriangleMesh mesh;
  for (const Station& st : stations)
    for (std::uint32_t j = 0; j < section; ++j) {
      const double theta = kTwoPi * j / section;
      mesh.vertices.push_back(st.centre +
                              radius * (std::cos(theta) * st.normal + std::sin(theta) * Vec3::UnitZ()));
    }
  const auto rings = static_cast<std::uint32_t>(stations.size());
  stitchRings(mesh, 0, rings, section, /*wrap=*/false);
  // Each end fan runs its ring the other way round from the walls beside it.
  capRing(mesh, 0, section, stations.front().centre, /*reversed=*/false);
  capRing(mesh, (rings - 1) * section, section, stations.back().centre, /*reversed=*/true);
  return outward(std::move(mesh));
}

TriangleMesh makeBeamShape(BeamSection section, double thickness, double height, double length) {
  const std::vector<Vec2> polygon = sectionOf(section, thickness, height);
  const auto n = static_cast<std::uint32_t>(polygon.size());
  TriangleMesh mesh;
  // Two copies of the section, at z = 0 and z = length, centred on the origin.
  for (const double z : {0.0, length})
    for (const Vec2& p : polygon)
      mesh.vertices.emplace_back(p.x() - 0.5, p.y() - 0.5 * height, z - 0.5 * length);
  // Walls: for a counter-clockwise section, (bᵢ, bᵢ₊₁, tᵢ₊₁) faces out.
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    mesh.triangles.push_back({i, j, n + j});
    mesh.triangles.push_back({i, n + j, n + i});
  }
  // Ends: the top counter-clockwise seen from +z, the bottom reversed.
  for (const auto& t : earClip(polygon)) {
    mesh.triangles.push_back({n + t[0], n + t[1], n + t[2]});
    mesh.triangles.push_back({t[0], t[2], t[1]});
  }
  return mesh;
}

TriangleMesh makeStoneShape(double a, double b, double amplitude, int subdivisions, std::mt19937_64& rng) {
  // r(d) = 1 + Σ aₖ sin(fₖ d·nₖ + φₖ) over six waves of random direction, frequency and phase, their
  // amplitudes summing to `amplitude`: a smooth radius that never falls below 1 − amplitude.
  constexpr int kWaves = 6;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  std::array<Vec3, kWaves> directions;
  std::array<double, kWaves> weights{}, frequencies{}, phases{};
  double total = 0.0;
  for (int k = 0; k < kWaves; ++k) {
    directions[k] = detail::drawVector([&] { return normal(rng); }).normalized();
    frequencies[k] = 1.0 + 2.5 * unit(rng);
    phases[k] = kTwoPi * unit(rng);
    weights[k] = 0.2 + unit(rng);
    total += weights[k];
  }
  TriangleMesh mesh = core::makeIcosphere(1.0, subdivisions);
  for (Vec3& p : mesh.vertices) {
    const Vec3 d = p.normalized();
    double r = 1.0;
    for (int k = 0; k < kWaves; ++k)
      r += amplitude * weights[k] / total * std::sin(frequencies[k] * d.dot(directions[k]) + phases[k]);
    p = (r * d).cwiseProduct(Vec3(1.0, a, b));
  }
  return mesh;
}

}  // namespace shapedb::volume::detail
