#include "codec.h"

#include <cmath>
#include <limits>
#include <zlib.h>

#include <shapedb/core/material.h>

namespace shapedb::io {
namespace {

Error corrupted(const char* what) {
  return Error{ErrorCode::kParse, std::string("corrupted ") + what + " blob"};
}

void putVec3(ByteWriter& w, const core::Vec3& v) {
  for (int k = 0; k < 3; ++k)
    w.put(v[k]);
}
bool getVec3(ByteReader& r, core::Vec3& v) {
  return r.get(v[0]) && r.get(v[1]) && r.get(v[2]);
}
void putMat3(ByteWriter& w, const core::Mat3& m) {
  for (int i = 0; i < 9; ++i)
    w.put(m.data()[i]);
}
bool getMat3(ByteReader& r, core::Mat3& m) {
  for (int i = 0; i < 9; ++i)
    if (!r.get(m.data()[i])) return false;
  return true;
}

/// Finite and at least `low`: what every stored size, weight or frequency must be. A blob whose checksum
/// matches but whose values are not (a hostile file) is as corrupted as one whose checksum does not.
bool finiteAtLeast(double v, double low) {
  return std::isfinite(v) && v >= low;
}

/// The head of an encoded ModalData: its Poisson ratio and rigid eigenvalues into `modes`, its shapes'
/// rows and its mode count; false where they are not what encodeModes writes (or the blob cannot hold
/// `count` modes of `rows` values).
bool readModesHead(ByteReader& r, core::ModalData& modes, std::uint32_t& rows, std::uint32_t& count) {
  if (!(r.get(modes.poissonRatio) && r.get(rows) && r.get(count))) return false;
  for (double& v : modes.rigidEigenvalues)
    if (!r.get(v) || !std::isfinite(v)) return false;
  return r.has(count, 16 + 2 * std::size_t{rows}) && rows % 3 == 0 &&
         core::validPoissonRatio(modes.poissonRatio);
}

}  // namespace

std::uint32_t checksum(const void* data, std::size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  const auto* p = static_cast<const Bytef*>(data);
  while (size > 0) {  // zlib takes uInt lengths
    const auto chunk = static_cast<uInt>(std::min<std::size_t>(size, 1u << 30));
    crc = crc32(crc, p, chunk);
    p += chunk;
    size -= chunk;
  }
  return static_cast<std::uint32_t>(crc);
}
std::uint32_t checksum(const Bytes& bytes) {
  return checksum(bytes.data(), bytes.size());
}

Bytes encodeDescriptor(const core::Descriptor& d) {
  ByteWriter w;
  w.put(static_cast<std::uint8_t>(d.kind));
  w.put(static_cast<std::uint8_t>(d.sampling));
  w.put(static_cast<std::uint16_t>(d.gridSize));
  putVec3(w, d.moments);
  w.put(d.cellSize);
  w.put(static_cast<std::uint32_t>(d.cells.size()));
  w.put(static_cast<std::uint8_t>(d.centroids.empty() ? 0 : 1));
  w.put(static_cast<std::uint8_t>(d.weights.empty() ? 0 : 1));
  for (std::size_t i = 0; i < d.cells.size(); ++i) {
    w.put(d.cells[i]);
    if (!d.centroids.empty()) putVec3(w, d.centroids[i]);
    if (!d.weights.empty()) w.put(d.weights[i]);
  }
  return std::move(w).take();
}

Result<core::Descriptor> decodeDescriptor(const void* data, std::size_t size) {
  ByteReader r(data, size);
  core::Descriptor d;
  std::uint8_t kind = 0, sampling = 0, hasCentroids = 0, hasWeights = 0;
  std::uint16_t grid = 0;
  std::uint32_t cells = 0;
  if (!(r.get(kind) && r.get(sampling) && r.get(grid) && getVec3(r, d.moments) && r.get(d.cellSize) &&
        r.get(cells) && r.get(hasCentroids) && r.get(hasWeights)))
    return corrupted("descriptor");
  if (kind > 2 || sampling > 1 || hasCentroids > 1 || hasWeights > 1) return corrupted("descriptor");
  d.kind = static_cast<core::DescriptorKind>(kind);
  d.sampling = static_cast<core::Sampling>(sampling);
  d.gridSize = grid;
  const std::size_t item = 4 + (hasCentroids ? 24 : 0) + (hasWeights ? 8 : 0);
  if (!r.has(cells, item)) return corrupted("descriptor");
  d.cells.resize(cells);
  if (hasCentroids) d.centroids.resize(cells);
  if (hasWeights) d.weights.resize(cells);
  for (std::size_t i = 0; i < cells; ++i) {
    r.get(d.cells[i]);
    if (hasCentroids) getVec3(r, d.centroids[i]);
    if (hasWeights) r.get(d.weights[i]);
    if ((hasCentroids && !d.centroids[i].allFinite()) || (hasWeights && !std::isfinite(d.weights[i])))
      return corrupted("descriptor");
  }
  if (!r.atEnd() || !d.moments.allFinite() || !finiteAtLeast(d.cellSize, 0.0)) return corrupted("descriptor");
  return d;
}

Bytes encodeTetMesh(const core::TetMesh& mesh) {
  // Nodes in double precision: linking (core/adapt.h) reproduces surface positions from them.
  ByteWriter w;
  w.put(static_cast<std::uint32_t>(mesh.nodes.size()));
  w.put(static_cast<std::uint32_t>(mesh.tets.size()));
  for (const core::Vec3& p : mesh.nodes)
    putVec3(w, p);
  for (const auto& t : mesh.tets)
    for (std::uint32_t v : t)
      w.put(v);
  return std::move(w).take();
}

Result<core::TetMesh> decodeTetMesh(const void* data, std::size_t size) {
  ByteReader r(data, size);
  std::uint32_t nodes = 0, tets = 0;
  if (!(r.get(nodes) && r.get(tets)) || !r.has(nodes, 24)) return corrupted("tet mesh");
  core::TetMesh mesh;
  mesh.nodes.resize(nodes);
  for (core::Vec3& p : mesh.nodes)
    if (!getVec3(r, p) || !p.allFinite()) return corrupted("tet mesh");
  if (!r.has(tets, 16)) return corrupted("tet mesh");
  mesh.tets.resize(tets);
  for (auto& t : mesh.tets)
    for (std::uint32_t& v : t)
      r.get(v);
  if (!r.atEnd()) return corrupted("tet mesh");
  if (Status valid = core::validateTetMesh(mesh); !valid) return corrupted("tet mesh");
  return mesh;
}

Bytes encodeModes(const core::ModalData& modes) {
  ByteWriter w;
  const auto rows = static_cast<std::uint32_t>(modes.shapes.rows());
  const auto count = static_cast<std::uint32_t>(modes.modeCount());
  w.put(modes.poissonRatio);
  w.put(rows);
  w.put(count);
  for (double r : modes.rigidEigenvalues)
    w.put(r);
  for (std::uint32_t i = 0; i < count; ++i) {
    w.put(modes.eigenvalues[i]);
    double largest = 0.0;
    for (std::uint32_t j = 0; j < rows; ++j)
      largest = std::max(largest, std::abs(modes.shapes(j, i)));
    const double scale = largest > 0.0 ? largest / 32767.0 : 1.0;
    w.put(scale);
    for (std::uint32_t j = 0; j < rows; ++j)
      w.put(static_cast<std::int16_t>(std::lround(modes.shapes(j, i) / scale)));
  }
  return std::move(w).take();
}

Result<core::ModalData> decodeModes(const void* data, std::size_t size) {
  ByteReader r(data, size);
  core::ModalData modes;
  std::uint32_t rows = 0, count = 0;
  if (!readModesHead(r, modes, rows, count)) return corrupted("modes");
  modes.eigenvalues.resize(count);
  modes.shapes.resize(rows, count);
  for (std::uint32_t i = 0; i < count; ++i) {
    double scale = 0.0;
    r.get(modes.eigenvalues[i]);
    r.get(scale);
    for (std::uint32_t j = 0; j < rows; ++j) {
      std::int16_t q = 0;
      r.get(q);
      modes.shapes(j, i) = q * scale;
    }
    // A finite scale can still overflow against the largest 16-bit value: the shape itself must be finite.
    if (!(std::isfinite(modes.eigenvalues[i]) && modes.eigenvalues[i] > 0.0 && std::isfinite(scale) &&
          modes.shapes.col(i).allFinite()))
      return corrupted("modes");
  }
  if (!r.atEnd()) return corrupted("modes");
  return modes;
}

Result<Eigen::VectorXd> decodeEigenvalues(const void* data, std::size_t size) {
  ByteReader r(data, size);
  core::ModalData head;
  std::uint32_t rows = 0, count = 0;
  if (!readModesHead(r, head, rows, count)) return corrupted("modes");
  Eigen::VectorXd eigenvalues(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    double scale = 0.0;
    r.get(eigenvalues[i]);
    r.get(scale);
    r.skip(rows, sizeof(std::int16_t));
    if (!(std::isfinite(eigenvalues[i]) && eigenvalues[i] > 0.0 && std::isfinite(scale)))
      return corrupted("modes");
  }
  if (!r.atEnd()) return corrupted("modes");
  return eigenvalues;
}

Bytes encodeMassProperties(const core::MassProperties& m) {
  ByteWriter w;
  w.put(m.density);
  w.put(m.volume);
  w.put(m.mass);
  putVec3(w, m.centerOfMass);
  putMat3(w, m.inertia);
  return std::move(w).take();
}

Result<core::MassProperties> decodeMassProperties(const void* data, std::size_t size) {
  ByteReader r(data, size);
  core::MassProperties m;
  if (!(r.get(m.density) && r.get(m.volume) && r.get(m.mass) && getVec3(r, m.centerOfMass) &&
        getMat3(r, m.inertia)) ||
      !r.atEnd() || !(m.density > 0.0 && m.volume > 0.0 && m.mass > 0.0) ||
      !(std::isfinite(m.density) && std::isfinite(m.volume) && std::isfinite(m.mass)) ||
      !m.centerOfMass.allFinite() || !m.inertia.allFinite())
    return corrupted("mass properties");
  return m;
}

Bytes encodeCollision(const core::CollisionCompound& c) {
  ByteWriter w;
  w.put(c.coverage);
  w.put(c.overshoot);
  w.put(static_cast<std::uint32_t>(c.shapes.size()));
  for (const core::CollisionShape& s : c.shapes) {
    w.put(static_cast<std::uint8_t>(s.type));
    putVec3(w, s.center);
    putMat3(w, s.rotation);
    putVec3(w, s.halfExtents);
    w.put(s.radius);
    w.put(s.halfLength);
  }
  return std::move(w).take();
}

Result<core::CollisionCompound> decodeCollision(const void* data, std::size_t size) {
  ByteReader r(data, size);
  core::CollisionCompound c;
  std::uint32_t count = 0;
  if (!(r.get(c.coverage) && r.get(c.overshoot) && r.get(count)) || !r.has(count, 1 + 8 * 17))
    return corrupted("collision");
  c.shapes.resize(count);
  for (core::CollisionShape& s : c.shapes) {
    std::uint8_t type = 0;
    r.get(type);
    if (type > 2) return corrupted("collision");
    s.type = static_cast<core::CollisionShape::Type>(type);
    getVec3(r, s.center);
    getMat3(r, s.rotation);
    getVec3(r, s.halfExtents);
    r.get(s.radius);
    r.get(s.halfLength);
    if (!s.center.allFinite() || !s.rotation.allFinite() || !s.halfExtents.allFinite() ||
        s.halfExtents.minCoeff() < 0.0 || !finiteAtLeast(s.radius, 0.0) || !finiteAtLeast(s.halfLength, 0.0))
      return corrupted("collision");
  }
  if (!r.atEnd() || !std::isfinite(c.coverage) || !std::isfinite(c.overshoot)) return corrupted("collision");
  return c;
}

Bytes encodeSound(const core::SoundData& s) {
  ByteWriter w;
  w.put(s.damping.alpha);
  w.put(s.damping.beta);
  w.put(static_cast<std::uint32_t>(s.frequenciesHz.size()));
  for (Eigen::Index i = 0; i < s.frequenciesHz.size(); ++i)
    w.put(s.frequenciesHz[i]);
  return std::move(w).take();
}

Result<core::SoundData> decodeSound(const void* data, std::size_t size) {
  ByteReader r(data, size);
  core::SoundData s;
  std::uint32_t count = 0;
  if (!(r.get(s.damping.alpha) && r.get(s.damping.beta) && r.get(count)) || !r.has(count, 8))
    return corrupted("sound");
  s.frequenciesHz.resize(count);
  for (std::uint32_t i = 0; i < count; ++i)
    if (!r.get(s.frequenciesHz[i]) || !finiteAtLeast(s.frequenciesHz[i], 0.0)) return corrupted("sound");
  if (!r.atEnd() || !finiteAtLeast(s.damping.alpha, 0.0) || !finiteAtLeast(s.damping.beta, 0.0))
    return corrupted("sound");
  return s;
}

}  // namespace shapedb::io
