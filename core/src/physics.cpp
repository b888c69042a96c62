#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <tuple>

#include <shapedb/core/disjoint_sets.h>
#include <shapedb/core/physics.h>

namespace shapedb::core {

double tetVolume(const TetMesh& mesh, std::size_t t) {
  const auto& [a, b, c, d] = mesh.tets[t];
  const Vec3& pa = mesh.nodes[a];
  return (mesh.nodes[b] - pa).cross(mesh.nodes[c] - pa).dot(mesh.nodes[d] - pa) / 6.0;
}

double flatTetVolume(const TetMesh& mesh) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : mesh.nodes) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return 1e-15 * std::pow((hi - lo).maxCoeff(), 3);
}

Status validateTetMesh(const TetMesh& mesh) {
  if (mesh.nodes.empty() || mesh.tets.empty()) return Error{ErrorCode::kEmptyMesh, "tet mesh has no tets"};
  for (const Vec3& p : mesh.nodes)
    if (!p.allFinite()) return Error{ErrorCode::kNonFinite, "tet mesh has a non-finite node"};
  const std::size_t n = mesh.nodes.size();
  const double minVolume = flatTetVolume(mesh);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (std::uint32_t v : mesh.tets[t])
      if (v >= n)
        return Error{ErrorCode::kIndexOutOfRange, "tet " + std::to_string(t) + " refers to node " +
                                                      std::to_string(v) + " of " + std::to_string(n)};
    if (!(tetVolume(mesh, t) > minVolume))
      return Error{ErrorCode::kDegenerateFace, "tet " + std::to_string(t) + " is flat or inverted"};
  }
  return Ok{};
}

TetGradients tetGradients(const std::array<Vec3, 4>& corners) {
  // Rows of the inverse of [x_i − x_0] give ∇N_1..3; ∇N_0 = −Σ.
  Mat3 edges;
  for (int k = 0; k < 3; ++k)
    edges.col(k) = corners[static_cast<std::size_t>(k + 1)] - corners[0];
  TetGradients out;
  out.volume = edges.determinant() / 6.0;
  out.gradients.rightCols<3>() = edges.inverse().transpose();
  out.gradients.col(0) = -out.gradients.rightCols<3>().rowwise().sum();
  return out;
}

TetGradients tetGradients(const TetMesh& mesh, std::size_t t) {
  const auto& tet = mesh.tets[t];
  return tetGradients({mesh.nodes[tet[0]], mesh.nodes[tet[1]], mesh.nodes[tet[2]], mesh.nodes[tet[3]]});
}

MassProperties computeTetMassProperties(const TetMesh& mesh, double density) {
  // Integrals about a reference point inside the mesh's span, for round-off.
  Vec3 ref = Vec3::Zero();
  for (const Vec3& p : mesh.nodes)
    ref += p;
  ref /= static_cast<double>(mesh.nodes.size());

  double volume = 0.0;
  Vec3 first = Vec3::Zero();   // ∫ x dV
  Mat3 second = Mat3::Zero();  // ∫ x xᵀ dV
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& tet = mesh.tets[t];
    const double v = tetVolume(mesh, t);
    Vec3 sum = Vec3::Zero();
    Mat3 outer = Mat3::Zero();
    for (std::uint32_t i : tet) {
      const Vec3 p = mesh.nodes[i] - ref;
      sum += p;
      outer += p * p.transpose();
    }
    // Over a tet: ∫ x dV = V Σp/4, ∫ x xᵀ dV = V (Σ p pᵀ + Σp Σpᵀ) / 20.
    volume += v;
    first += v * sum / 4.0;
    second += v * (outer + sum * sum.transpose()) / 20.0;
  }
  MassProperties result;
  result.density = density;
  result.volume = volume;
  result.mass = density * volume;
  const Vec3 c = first / volume;
  result.centerOfMass = ref + c;
  result.inertia = inertiaFromCovariance(density * (second - volume * c * c.transpose()));
  return result;
}

std::vector<BoundaryFace> boundaryFaces(const TetMesh& mesh) {
  // A face seen by one tet only is on the boundary. Faces of a positively oriented tet (a, b, c, d),
  // wound outward: (a, c, b), (a, b, d), (b, c, d), (a, d, c), each across from one corner. The faces are
  // counting-sorted by their smallest node, and each node's few faces sorted by the other two (ties by
  // tet, so that the order is fixed): an inner face is two equal keys in a row. One pass over the faces
  // where one sort of all of them took O(F log F): a locator is built for every entry a query fetches.
  // A face's sorted nodes are its tet's sorted nodes less the corner across from it, so a tet's four
  // nodes are sorted once.
  std::uint32_t nodes = 0;
  for (const TetMesh::Tet& tet : mesh.tets)
    for (const std::uint32_t v : tet)
      nodes = std::max(nodes, v + 1);
  struct Keyed {
    std::uint32_t first, second, third;  // the face's nodes, sorted
    BoundaryFace face;
  };
  std::vector<Keyed> keyed(4 * mesh.tets.size());
  std::vector<std::uint32_t> begin(static_cast<std::size_t>(nodes) + 1, 0);
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& [a, b, c, d] = mesh.tets[t];
    std::array<std::uint32_t, 4> sorted{a, b, c, d};
    std::sort(sorted.begin(), sorted.end());
    const std::array<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>, 4> faces{
        {{{a, c, b}, d}, {{a, b, d}, c}, {{b, c, d}, a}, {{a, d, c}, b}}};
    for (std::size_t f = 0; f < 4; ++f) {
      const auto& [nodesOf, across] = faces[f];
      // The tet's sorted nodes less one occurrence of the corner across: the face's own, sorted.
      std::array<std::uint32_t, 3> key{};
      bool skipped = false;
      for (std::size_t i = 0, k = 0; i < 4; ++i) {
        if (!skipped && sorted[i] == across) {
          skipped = true;
          continue;
        }
        key[k++] = sorted[i];
      }
      Keyed& out = keyed[4 * t + f];
      out = {key[0], key[1], key[2], BoundaryFace{nodesOf, t}};
      ++begin[key[0] + 1];
    }
  }
  std::partial_sum(begin.begin(), begin.end(), begin.begin());
  std::vector<Keyed> faces(keyed.size());
  {
    std::vector<std::uint32_t> next(begin.begin(), begin.end() - 1);
    for (const Keyed& k : keyed)
      faces[next[k.first]++] = k;
  }

  std::vector<BoundaryFace> out;
  for (std::uint32_t v = 0; v < nodes; ++v) {
    const auto first = faces.begin() + begin[v], last = faces.begin() + begin[v + 1];
    std::sort(first, last, [](const Keyed& x, const Keyed& y) {
      return std::tie(x.second, x.third, x.face.tet) < std::tie(y.second, y.third, y.face.tet);
    });
    for (auto i = first; i != last;) {
      auto j = i + 1;
      while (j != last && j->second == i->second && j->third == i->third)
        ++j;
      if (j == i + 1) out.push_back(i->face);
      i = j;
    }
  }
  return out;
}

std::size_t faceConnectedPieces(const TetMesh& mesh) {
  // Every face keyed by its sorted nodes; two equal keys in a row are a face two tets share: join them.
  std::vector<std::pair<std::array<std::uint32_t, 3>, std::uint32_t>> faces;
  faces.reserve(4 * mesh.tets.size());
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& [a, b, c, d] = mesh.tets[t];
    for (std::array<std::uint32_t, 3> key :
         {std::array{a, b, c}, std::array{a, b, d}, std::array{a, c, d}, std::array{b, c, d}}) {
      std::sort(key.begin(), key.end());
      faces.emplace_back(key, t);
    }
  }
  std::sort(faces.begin(), faces.end());
  DisjointSets pieces(mesh.tets.size());
  for (std::size_t i = 0; i + 1 < faces.size(); ++i)
    if (faces[i].first == faces[i + 1].first) pieces.unite(faces[i].second, faces[i + 1].second);
  return pieces.sets();
}

TriangleMesh boundarySurface(const TetMesh& mesh) {
  TriangleMesh surface;
  std::vector<std::uint32_t> remap(mesh.nodes.size(), UINT32_MAX);
  for (const BoundaryFace& face : boundaryFaces(mesh)) {
    TriangleMesh::Triangle triangle;
    for (int i = 0; i < 3; ++i) {
      std::uint32_t& r = remap[face.nodes[static_cast<std::size_t>(i)]];
      if (r == UINT32_MAX) {
        r = static_cast<std::uint32_t>(surface.vertices.size());
        surface.vertices.push_back(mesh.nodes[face.nodes[static_cast<std::size_t>(i)]]);
      }
      triangle[static_cast<std::size_t>(i)] = r;
    }
    surface.triangles.push_back(triangle);
  }
  return surface;
}

Eigen::VectorXd ModalData::frequenciesHz() const {
  Eigen::VectorXd hz(eigenvalues.size());
  for (Eigen::Index i = 0; i < eigenvalues.size(); ++i)
    hz[i] = std::sqrt(std::max(eigenvalues[i], 0.0)) / (2.0 * std::numbers::pi);
  return hz;
}

bool CollisionShape::contains(const Vec3& p) const {
  const Vec3 local = rotation.transpose() * (p - center);
  switch (type) {
    case Type::kSphere:
      return local.squaredNorm() <= radius * radius;
    case Type::kBox:
      return (local.cwiseAbs() - halfExtents).maxCoeff() <= 0.0;
    case Type::kCapsule: {
      const double z = std::clamp(local.z(), -halfLength, halfLength);
      return (local - Vec3(0.0, 0.0, z)).squaredNorm() <= radius * radius;
    }
  }
  return false;
}

double CollisionShape::volume() const {
  const double ball = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  switch (type) {
    case Type::kSphere:
      return ball;
    case Type::kBox:
      return 8.0 * halfExtents.prod();
    case Type::kCapsule:
      return ball + std::numbers::pi * radius * radius * 2.0 * halfLength;
  }
  return 0.0;
}

Vec3 CollisionShape::halfSpan() const {
  switch (type) {
    case Type::kSphere:
      return Vec3::Constant(radius);
    case Type::kBox:
      return rotation.cwiseAbs() * halfExtents;
    case Type::kCapsule:
      return rotation.col(2).cwiseAbs() * halfLength + Vec3::Constant(radius);
  }
  return Vec3::Zero();
}

const char* toString(CollisionShape::Type type) {
  switch (type) {
    case CollisionShape::Type::kSphere:
      return "sphere";
    case CollisionShape::Type::kBox:
      return "box";
    case CollisionShape::Type::kCapsule:
      return "capsule";
  }
  return "?";
}

}  // namespace shapedb::core
