#pragma once

// Binary blobs of the database file: little-endian, fixed-width, versioned by the schema. Every decoder
// checks sizes and values against the bytes it has: a corrupted or truncated blob is an error, never an
// out-of-bounds read.

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include <shapedb/core/descriptor.h>
#include <shapedb/core/physics.h>
#include <shapedb/core/result.h>

namespace shapedb::io {

using Bytes = std::vector<std::uint8_t>;

class ByteWriter {
 public:
  template <typename T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    mBytes.insert(mBytes.end(), p, p + sizeof(T));
  }
  Bytes take() && { return std::move(mBytes); }

 private:
  Bytes mBytes;
};

class ByteReader {
 public:
  ByteReader(const void* data, std::size_t size)
      : mData(static_cast<const std::uint8_t*>(data)), mSize(size) {}
  /// Reads a T; false (and the reader stays failed) past the end.
  template <typename T>
  bool get(T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (mFailed || mSize - mOffset < sizeof(T)) return !(mFailed = true);
    std::memcpy(&value, mData + mOffset, sizeof(T));
    mOffset += sizeof(T);
    return true;
  }
  /// Whether `count` items of `itemBytes` each can still be read: guards allocations sized from the blob.
  bool has(std::uint64_t count, std::size_t itemBytes) const {
    return !mFailed && count <= (mSize - mOffset) / itemBytes;
  }
  /// Passes over `count` items of `itemBytes` each; false (and the reader stays failed) past the end.
  bool skip(std::uint64_t count, std::size_t itemBytes) {
    if (!has(count, itemBytes)) return !(mFailed = true);
    mOffset += static_cast<std::size_t>(count) * itemBytes;
    return true;
  }
  bool ok() const { return !mFailed; }
  bool atEnd() const { return !mFailed && mOffset == mSize; }

 private:
  const std::uint8_t* mData;
  std::size_t mSize;
  std::size_t mOffset = 0;
  bool mFailed = false;
};

/// CRC-32 (zlib's) of a blob: stored beside it, checked when it is read.
std::uint32_t checksum(const Bytes& bytes);
std::uint32_t checksum(const void* data, std::size_t size);

Bytes encodeDescriptor(const core::Descriptor& d);
Result<core::Descriptor> decodeDescriptor(const void* data, std::size_t size);

Bytes encodeTetMesh(const core::TetMesh& mesh);
Result<core::TetMesh> decodeTetMesh(const void* data, std::size_t size);

/// Mode shapes are stored as 16-bit integers per mode, scaled to the mode's largest component: a relative
/// error below 2⁻¹⁵ of it, far under the discretization error of the FEM, at a quarter of the bytes.
Bytes encodeModes(const core::ModalData& modes);
Result<core::ModalData> decodeModes(const void* data, std::size_t size);
/// The eigenvalues of an encoded ModalData alone, its shapes passed over (checked as decodeModes checks
/// the blob's layout and the eigenvalues, not the shapes' values): what a spectrum needs, without the
/// bulk of the entry.
Result<Eigen::VectorXd> decodeEigenvalues(const void* data, std::size_t size);

Bytes encodeMassProperties(const core::MassProperties& m);
Result<core::MassProperties> decodeMassProperties(const void* data, std::size_t size);

Bytes encodeCollision(const core::CollisionCompound& c);
Result<core::CollisionCompound> decodeCollision(const void* data, std::size_t size);

Bytes encodeSound(const core::SoundData& s);
Result<core::SoundData> decodeSound(const void* data, std::size_t size);

}  // namespace shapedb::io
