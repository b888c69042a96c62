#include "text_mesh_readers.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>

namespace shapedb::io::detail {
namespace {

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/// Splits a line into whitespace-separated words, one at a time.
class Words {
 public:
  explicit Words(std::string_view line) : mRest(line) {}
  bool next(std::string_view& word) {
    std::size_t begin = 0;
    while (begin < mRest.size() && isSpace(mRest[begin]))
      ++begin;
    std::size_t end = begin;
    while (end < mRest.size() && !isSpace(mRest[end]))
      ++end;
    word = mRest.substr(begin, end - begin);
    mRest.remove_prefix(end);
    return !word.empty();
  }

 private:
  std::string_view mRest;
};

std::string quoted(std::string_view word) {
  constexpr std::size_t kMax = 40;
  std::string out(1, '\'');
  out.append(word.substr(0, kMax));
  out.append(word.size() > kMax ? "...'" : "'");
  return out;
}

enum class Parsed { kOk, kNotANumber, kNonFinite };

/// A whole word as a finite double.
Parsed parseCoordinate(std::string_view word, double& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (ec == std::errc::result_out_of_range) return Parsed::kNonFinite;
  if (ec != std::errc() || end != word.data() + word.size()) return Parsed::kNotANumber;
  return std::isfinite(value) ? Parsed::kOk : Parsed::kNonFinite;
}

/// A whole word as an integer.
bool parseInteger(std::string_view word, long long& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc() && end == word.data() + word.size();
}

std::optional<std::string> readAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return std::nullopt;
  return bytes;
}

}  // namespace

Result<RawPolygons> readObj(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{ErrorCode::kIo, path.string() + ": cannot read file"};
  RawPolygons raw;
  std::string line;
  std::size_t number = 0, statement = 0;  // the line read last, and the one the statement starts on
  auto fail = [&](ErrorCode code, const std::string& message) {
    return Error{code, path.string() + ": line " + std::to_string(statement) + ": " + message};
  };
  while (std::getline(in, line)) {
    statement = ++number;
    // A backslash at the end of a line continues the statement on the next (the format allows it; long
    // face lines are written so). Errors name the statement's first line.
    for (std::string next;;) {
      const std::size_t end = line.find_last_not_of(" \t\r");
      if (end == std::string::npos || line[end] != '\\' || !std::getline(in, next)) break;
      ++number;
      line.resize(end);  // the backslash and what follows it
      line += ' ';
      line += next;
    }
    Words words(line);
    std::string_view keyword;
    if (!words.next(keyword)) continue;
    if (keyword == "v") {
      double xyz[3] = {};
      for (double& c : xyz) {
        std::string_view word;
        if (!words.next(word)) return fail(ErrorCode::kParse, "a vertex needs three coordinates");
        const Parsed parsed = parseCoordinate(word, c);
        if (parsed == Parsed::kNonFinite)
          return fail(ErrorCode::kNonFinite, "non-finite number " + quoted(word));
        if (parsed == Parsed::kNotANumber)
          return fail(ErrorCode::kParse, "cannot parse coordinate " + quoted(word));
      }
      raw.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
    } else if (keyword == "f") {
      std::string_view corner;
      const std::size_t first = raw.corners.size();
      while (words.next(corner)) {
        const std::string_view index = corner.substr(0, corner.find('/'));
        long long value = 0;
        const auto [end, ec] = std::from_chars(index.data(), index.data() + index.size(), value);
        if (ec == std::errc::result_out_of_range)
          return fail(ErrorCode::kIndexOutOfRange, "vertex index " + quoted(index) + " out of range");
        if (ec != std::errc() || end != index.data() + index.size())
          return fail(ErrorCode::kParse, "face corner " + quoted(corner) + " has no vertex index");
        // 1-based; negative counts back from the last vertex read so far.
        const long long vertices = static_cast<long long>(raw.vertices.size());
        const long long zeroBased = value > 0 ? value - 1 : vertices + value;
        if (value == 0 || zeroBased < 0 || zeroBased >= static_cast<long long>(RawPolygons::kInvalidIndex))
          return fail(ErrorCode::kIndexOutOfRange, "vertex index " + std::to_string(value) + " out of range");
        const auto corner32 = static_cast<std::uint32_t>(zeroBased);
        if (raw.corners.size() == first || raw.corners.back() != corner32) raw.corners.push_back(corner32);
      }
      if (raw.corners.size() - first > 1 && raw.corners.back() == raw.corners[first]) raw.corners.pop_back();
      raw.endPolygon();
    }
  }
  if (in.bad()) return Error{ErrorCode::kIo, path.string() + ": read error"};
  // Forward references are allowed while reading; every index must name a vertex in the end.
  for (std::uint32_t corner : raw.corners)
    if (corner >= raw.vertices.size())
      return Error{ErrorCode::kIndexOutOfRange, path.string() + ": vertex index " +
                                                    std::to_string(corner + 1) + " out of range (" +
                                                    std::to_string(raw.vertices.size()) + " vertices)"};
  return raw;
}

Result<RawPolygons> readOff(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{ErrorCode::kIo, path.string() + ": cannot read file"};
  std::string line;
  std::size_t number = 0;
  auto fail = [&](ErrorCode code, const std::string& message) {
    return Error{code, path.string() + ": line " + std::to_string(number) + ": " + message};
  };
  // The next line with a word on it (comments and blank lines skipped); false at the end of the file.
  auto nextLine = [&](Words& words, std::string_view& first) {
    while (std::getline(in, line)) {
      ++number;
      if (const std::size_t hash = line.find('#'); hash != std::string::npos) line.erase(hash);
      words = Words(line);
      if (words.next(first)) return true;
    }
    return false;
  };
  Words words("");
  std::string_view word;
  if (!nextLine(words, word)) return Error{ErrorCode::kParse, path.string() + ": no OFF header"};
  const std::string_view header = word;
  const bool known = header == "OFF" || header == "COFF" || header == "NOFF" || header == "CNOFF" ||
                     header == "STOFF" || header == "STCOFF" || header == "STNOFF" || header == "STCNOFF";
  if (!known) {
    if (header.size() >= 3 && header.substr(header.size() - 3) == "OFF")
      return fail(ErrorCode::kParse, "unsupported OFF variant " + quoted(header) + " (3D ASCII OFF only)");
    return fail(ErrorCode::kParse, "not an OFF file (no OFF header)");
  }
  // The counts follow on the header line or on the next one.
  long long counts[3] = {0, 0, 0};
  std::string_view count;
  if (!words.next(count) && !nextLine(words, count))
    return fail(ErrorCode::kParse, "no vertex and face counts");
  if (count == "BINARY") return fail(ErrorCode::kParse, "binary OFF is not supported");
  for (int i = 0; i < 2; ++i) {
    if (i > 0 && !words.next(count)) return fail(ErrorCode::kParse, "no face count");
    if (!parseInteger(count, counts[i]) || counts[i] < 0)
      return fail(ErrorCode::kParse, "bad count " + quoted(count));
  }
  RawPolygons raw;
  // Never reserve on a header's word: the lines below are what there is.
  for (long long v = 0; v < counts[0]; ++v) {
    if (!nextLine(words, word))
      return Error{ErrorCode::kParse, path.string() + ": the header says " + std::to_string(counts[0]) +
                                          " vertices, the file ends after " + std::to_string(v)};
    double xyz[3] = {};
    for (int c = 0; c < 3; ++c) {
      if (c > 0 && !words.next(word)) return fail(ErrorCode::kParse, "a vertex needs three coordinates");
      const Parsed parsed = parseCoordinate(word, xyz[c]);
      if (parsed == Parsed::kNonFinite)
        return fail(ErrorCode::kNonFinite, "non-finite number " + quoted(word));
      if (parsed == Parsed::kNotANumber)
        return fail(ErrorCode::kParse, "cannot parse coordinate " + quoted(word));
    }
    raw.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  for (long long f = 0; f < counts[1]; ++f) {
    if (!nextLine(words, word))
      return Error{ErrorCode::kParse, path.string() + ": the header says " + std::to_string(counts[1]) +
                                          " faces, the file ends after " + std::to_string(f)};
    long long corners = 0;
    if (!parseInteger(word, corners) || corners < 0)
      return fail(ErrorCode::kParse, "bad corner count " + quoted(word));
    for (long long k = 0; k < corners; ++k) {
      long long index = 0;
      if (!words.next(word)) return fail(ErrorCode::kParse, "the face has fewer indices than its count");
      if (!parseInteger(word, index)) return fail(ErrorCode::kParse, "bad vertex index " + quoted(word));
      if (index < 0 || index >= static_cast<long long>(RawPolygons::kInvalidIndex))
        return fail(ErrorCode::kIndexOutOfRange, "vertex index " + std::to_string(index) + " out of range");
      raw.corners.push_back(static_cast<std::uint32_t>(index));
    }
    raw.endPolygon();
  }
  if (in.bad()) return Error{ErrorCode::kIo, path.string() + ": read error"};
  return raw;
}

namespace {

enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<ScalarType> parseScalarType(std::string_view name) {
  if (name == "char" || name == "int8") return ScalarType::kInt8;
  if (name == "uchar" || name == "uint8") return ScalarType::kUint8;
  if (name == "short" || name == "int16") return ScalarType::kInt16;
  if (name == "ushort" || name == "uint16") return ScalarType::kUint16;
  if (name == "int" || name == "int32") return ScalarType::kInt32;
  if (name == "uint" || name == "uint32") return ScalarType::kUint32;
  if (name == "float" || name == "float32") return ScalarType::kFloat32;
  if (name == "double" || name == "float64") return ScalarType::kFloat64;
  return std::nullopt;
}

std::size_t sizeOf(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32:
      return 4;
    case ScalarType::kFloat64:
      return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::kFloat32;
  bool isList = false;
  ScalarType countType = ScalarType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { kAscii, kLittleEndian, kBigEndian };

/// The body of a PLY file, read one value at a time in its encoding. Every read is checked against the
/// bytes that remain.
class PlyBody {
 public:
  PlyBody(std::string_view bytes, PlyFormat format) : mBytes(bytes), mFormat(format) {}

  /// One value as a double; false at the end of the data or on a word that is not a number of `type`.
  bool read(ScalarType type, double& value) {
    if (mFormat == PlyFormat::kAscii) {
      std::size_t begin = mAt;
      while (begin < mBytes.size() && (isSpace(mBytes[begin]) || mBytes[begin] == '\n'))
        ++begin;
      std::size_t end = begin;
      while (end < mBytes.size() && !isSpace(mBytes[end]) && mBytes[end] != '\n')
        ++end;
      mAt = end;
      const std::string_view word = mBytes.substr(begin, end - begin);
      if (word.empty()) return false;
      if (type == ScalarType::kFloat32 || type == ScalarType::kFloat64) {
        // Range problems are left to the caller's finiteness check.
        const auto [stop, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
        if (ec == std::errc::result_out_of_range) {
          value = std::numeric_limits<double>::infinity();
          return true;
        }
        return ec == std::errc() && stop == word.data() + word.size();
      }
      long long integer = 0;
      if (!parseInteger(word, integer)) return false;
      value = static_cast<double>(integer);
      return true;
    }
    const std::size_t size = sizeOf(type);
    if (mBytes.size() - mAt < size) return false;
    unsigned char raw[8];
    std::memcpy(raw, mBytes.data() + mAt, size);
    mAt += size;
    if ((mFormat == PlyFormat::kBigEndian) == (std::endian::native == std::endian::little))
      std::reverse(raw, raw + size);
    switch (type) {
      case ScalarType::kInt8:
        value = static_cast<std::int8_t>(raw[0]);
        break;
      case ScalarType::kUint8:
        value = raw[0];
        break;
      case ScalarType::kInt16:
        value = load<std::int16_t>(raw);
        break;
      case ScalarType::kUint16:
        value = load<std::uint16_t>(raw);
        break;
      case ScalarType::kInt32:
        value = load<std::int32_t>(raw);
        break;
      case ScalarType::kUint32:
        value = load<std::uint32_t>(raw);
        break;
      case ScalarType::kFloat32:
        value = load<float>(raw);
        break;
      case ScalarType::kFloat64:
        value = load<double>(raw);
        break;
    }
    return true;
  }

  /// Bytes left (binary), or characters left (ASCII: each value takes at least two).
  std::size_t remaining() const { return mBytes.size() - mAt; }
  bool isAscii() const { return mFormat == PlyFormat::kAscii; }

 private:
  template <typename T>
  static T load(const unsigned char* raw) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }

  std::string_view mBytes;
  std::size_t mAt = 0;
  PlyFormat mFormat;
};

}  // namespace

Result<RawPolygons> readPly(const std::filesystem::path& path) {
  const std::optional<std::string> file = readAll(path);
  if (!file) return Error{ErrorCode::kIo, path.string() + ": cannot read file"};
  auto fail = [&](const std::string& message) {
    return Error{ErrorCode::kParse, path.string() + ": " + message};
  };

  // The header: lines up to end_header, within the first MiB.
  constexpr std::size_t kMaxHeader = 1 << 20;
  const std::string_view bytes(*file);
  if (bytes.substr(0, 3) != "ply") return fail("not a PLY file (no 'ply' magic)");
  std::size_t at = 0;
  std::optional<PlyFormat> format;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (!ended) {
    const std::size_t newline = bytes.find('\n', at);
    if (newline == std::string_view::npos || newline > kMaxHeader)
      return fail("PLY header without end_header");
    Words words(bytes.substr(at, newline - at));
    at = newline + 1;
    std::string_view keyword;
    if (!words.next(keyword) || keyword == "ply" || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      ended = true;
    } else if (keyword == "format") {
      std::string_view name, version;
      words.next(name);
      words.next(version);
      if (name == "ascii")
        format = PlyFormat::kAscii;
      else if (name == "binary_little_endian")
        format = PlyFormat::kLittleEndian;
      else if (name == "binary_big_endian")
        format = PlyFormat::kBigEndian;
      else
        return fail("unknown PLY format " + quoted(name));
      if (version != "1.0") return fail("unsupported PLY version " + quoted(version));
    } else if (keyword == "element") {
      std::string_view name, count;
      long long n = 0;
      if (!words.next(name) || !words.next(count) || !parseInteger(count, n) || n < 0)
        return fail("bad element line in the PLY header");
      elements.push_back({std::string(name), static_cast<std::uint64_t>(n), {}});
    } else if (keyword == "property") {
      if (elements.empty()) return fail("PLY property before any element");
      PlyProperty property;
      std::string_view type, name;
      if (!words.next(type)) return fail("bad property line in the PLY header");
      if (type == "list") {
        std::string_view countType;
        if (!words.next(countType) || !words.next(type)) return fail("bad list property in the PLY header");
        const auto parsedCount = parseScalarType(countType);
        if (!parsedCount || *parsedCount == ScalarType::kFloat32 || *parsedCount == ScalarType::kFloat64)
          return fail("bad list count type " + quoted(countType) + " in the PLY header");
        property.isList = true;
        property.countType = *parsedCount;
      }
      const auto parsedType = parseScalarType(type);
      if (!parsedType) return fail("unknown PLY type " + quoted(type));
      if (!words.next(name)) return fail("PLY property without a name");
      property.type = *parsedType;
      property.name = std::string(name);
      elements.back().properties.push_back(std::move(property));
    } else {
      return fail("unknown PLY header line " + quoted(keyword));
    }
  }
  if (!format) return fail("PLY header without a format line");

  RawPolygons raw;
  PlyBody body(bytes.substr(at), *format);
  for (const PlyElement& element : elements) {
    const bool isVertex = element.name == "vertex", isFace = element.name == "face";
    int coordinate[3] = {-1, -1, -1};
    int indices = -1;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      for (int c = 0; c < 3; ++c)
        if (isVertex && !property.isList && property.name == std::string(1, static_cast<char>('x' + c)))
          coordinate[c] = static_cast<int>(p);
      if (isFace && property.isList && (property.name == "vertex_indices" || property.name == "vertex_index"))
        indices = static_cast<int>(p);
    }
    if (isVertex && (coordinate[0] < 0 || coordinate[1] < 0 || coordinate[2] < 0))
      return fail("the PLY vertex element has no x, y, z");
    if (isFace && indices < 0) return fail("the PLY face element has no vertex_indices list");
    auto truncated = [&](std::uint64_t item) {
      return fail("the file ends in " + element.name + " " + std::to_string(item) + " of " +
                  std::to_string(element.count) + " (truncated, or the header's count is wrong)");
    };
    // Every item takes at least a byte per property (a character in ASCII): a count the rest of the
    // file cannot hold is refused before any work, and an element without properties is nothing to read.
    if (element.properties.empty()) continue;
    std::size_t minimumItemBytes = 0;
    for (const PlyProperty& property : element.properties)
      minimumItemBytes += body.isAscii() ? 1 : sizeOf(property.isList ? property.countType : property.type);
    if (element.count > body.remaining() / minimumItemBytes)
      return fail("the header says " + std::to_string(element.count) + " " + element.name + " items, the " +
                  std::to_string(body.remaining()) + " bytes left in the file cannot hold them");
    for (std::uint64_t item = 0; item < element.count; ++item) {
      double xyz[3] = {};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.isList) {
          double value = 0.0;
          if (!body.read(property.type, value)) return truncated(item);
          for (int c = 0; c < 3; ++c)
            if (static_cast<int>(p) == coordinate[c]) xyz[c] = value;
          continue;
        }
        double count = 0.0;
        if (!body.read(property.countType, count)) return truncated(item);
        if (count < 0.0 || count * static_cast<double>(body.isAscii() ? 2 : sizeOf(property.type)) >
                               static_cast<double>(body.remaining()))
          return truncated(item);
        const auto n = static_cast<std::size_t>(count);
        for (std::size_t k = 0; k < n; ++k) {
          double value = 0.0;
          if (!body.read(property.type, value)) return truncated(item);
          if (static_cast<int>(p) != indices) continue;
          if (value < 0.0 || value >= static_cast<double>(RawPolygons::kInvalidIndex) ||
              value != std::floor(value))
            return Error{ErrorCode::kIndexOutOfRange, path.string() + ": face " + std::to_string(item) +
                                                          ": vertex index " + std::to_string(value) +
                                                          " out of range"};
          raw.corners.push_back(static_cast<std::uint32_t>(value));
        }
      }
      if (isVertex) {
        if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
          return Error{ErrorCode::kNonFinite,
                       path.string() + ": vertex " + std::to_string(item) + " has a non-finite coordinate"};
        raw.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
      if (isFace) raw.endPolygon();
    }
  }
  return raw;
}

}  // namespace shapedb::io::detail
