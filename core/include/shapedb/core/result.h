#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace shapedb {

/// Why an operation failed. Stable: the CLI maps these to messages and exit codes.
enum class ErrorCode {
  kIo,                       ///< a file could not be opened, read or written
  kUnknownFormat,            ///< the file's extension names no supported format
  kParse,                    ///< the file's content could not be parsed
  kEmptyMesh,                ///< no faces, or no vertices
  kNonFinite,                ///< a NaN or infinite coordinate
  kIndexOutOfRange,          ///< a face refers to a vertex that does not exist
  kDegenerateFace,           ///< a face with a repeated vertex or zero area
  kNotClosed,                ///< boundary edges: the surface does not enclose a volume
  kNonManifold,              ///< an edge shared by more than two faces
  kInconsistentOrientation,  ///< two faces traverse a shared edge in the same direction
  kInsideOut,                ///< the signed volume is negative
  kZeroVolume,               ///< the surface encloses no measurable volume
  kInvalidArgument,          ///< a parameter outside its documented range
  kCancelled,                ///< work abandoned before it was done: its owner shut down first
  kTooLarge,                 ///< the input would need more memory than there is
  kSelfIntersecting,         ///< the surface passes through itself: it bounds no solid to mesh
};

/// A recoverable failure: a code and a one-line message that names the input and the problem,
/// e.g. "fragment.obj: mesh is not closed (14 boundary edges)".
struct Error {
  ErrorCode code;
  std::string message;
};

/// The value of an operation that can fail recoverably, or the Error saying why it did not.
/// The caller must look at it: [[nodiscard]]. Immutable once made; copyable when T is.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : mData(std::move(value)) {}      // NOLINT: implicit by design, like std::expected
  Result(Error error) : mData(std::move(error)) {}  // NOLINT

  bool ok() const { return std::holds_alternative<T>(mData); }
  explicit operator bool() const { return ok(); }

  /// The value. Precondition: ok().
  const T& value() const& {
    assert(ok());
    return std::get<T>(mData);
  }
  T& value() & {
    assert(ok());
    return std::get<T>(mData);
  }
  T&& value() && {
    assert(ok());
    return std::get<T>(std::move(mData));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

  /// The error. Precondition: !ok().
  const Error& error() const {
    assert(!ok());
    return std::get<Error>(mData);
  }

 private:
  std::variant<T, Error> mData;
};

/// Result of an operation that returns nothing on success.
struct Ok {};
using Status = Result<Ok>;

/// Prefixes an error's message with the name of the input it concerns ("file.obj: ...").
inline Error withContext(Error error, const std::string& context) {
  error.message = context + ": " + error.message;
  return error;
}

}  // namespace shapedb
