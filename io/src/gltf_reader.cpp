#include "gltf_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <tiny_gltf.h>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <shapedb/core/triangle_mesh.h>

#include "mesh_format.h"

namespace shapedb::io::detail {
namespace {

using Transform = Eigen::Matrix4d;

Error fileError(const std::filesystem::path& path, ErrorCode code, const std::string& message) {
  return Error{code, path.string() + ": " + message};
}

// tinygltf's file system, narrowed: an external buffer or image is read only if it is a regular file (a
// URI naming a device or a pipe would block or never end), and paths are taken as they are (no `~`).
bool regularFileExists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

std::string pathAsIs(const std::string& path, void*) {
  return path;
}

bool readRegularFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (err) *err += "'" + path + "' is not a regular file\n";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!in || ec) {
    if (err) *err += "cannot read '" + path + "'\n";
    return false;
  }
  out->resize(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(size));
  return static_cast<std::uintmax_t>(in.gcount()) == size;
}

bool writeNothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "shapedb's glTF reader writes no file\n";
  return false;
}

// Images are materials' business, not a surface's: kept as the bytes they are, never decoded.
bool keepImageUndecoded(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                        const unsigned char*, int, void*) {
  return true;
}

int componentBytes(int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// One component at `at` (little-endian, as glTF stores it), as a double; normalized integers mapped to
// [0, 1] or [-1, 1] as glTF defines them.
double readComponent(const unsigned char* at, int componentType, bool normalized) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t v;
      std::memcpy(&v, at, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? at[0] / 255.0 : at[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, at, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, at, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, at, 4);
      return v;
    }
    default: {  // float
      float v;
      std::memcpy(&v, at, 4);
      return v;
    }
  }
}

// An accessor without a buffer view is zeros (then changed by its sparse values): its count costs memory
// the file does not hold, so it is bounded.
constexpr std::size_t kMaxUnbackedElements = std::size_t{1} << 24;

class Reader {
 public:
  Reader(const std::filesystem::path& path, const tinygltf::Model& model) : mPath(path), mModel(model) {}

  Result<RawPolygons> read(GltfReport& report) {
    for (const std::string& ext : mModel.extensionsRequired)
      if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression")
        return fileError(mPath, ErrorCode::kParse,
                         "its meshes are compressed (" + ext +
                             "), which shapedb does not decode: export them uncompressed");
    if (Status placed = placeScene(); !placed) return placed.error();
    report = mReport;
    if (mRaw.polygonCount() == 0)
      return fileError(mPath, ErrorCode::kEmptyMesh,
                       "the scene has no triangles" +
                           (mReport.primitivesSkipped > 0 ? " (" + std::to_string(mReport.primitivesSkipped) +
                                                                " point or line primitives)"
                                                          : std::string()));
    return std::move(mRaw);
  }

 private:
  Error parseError(const std::string& message) const { return fileError(mPath, ErrorCode::kParse, message); }

  // The meshes of the default scene (else the first; else of every root node; else every mesh), each
  // through its node's transform in the world. Iterative, so that a deep hierarchy cannot overflow the
  // stack; a node met twice on one path is a cycle.
  Status placeScene() {
    const std::size_t nodeCount = mModel.nodes.size();
    std::vector<int> roots;
    if (!mModel.scenes.empty()) {
      const int scene = mModel.defaultScene >= 0 ? mModel.defaultScene : 0;
      if (scene >= static_cast<int>(mModel.scenes.size()))
        return parseError("the default scene " + std::to_string(scene) + " does not exist");
      roots = mModel.scenes[static_cast<std::size_t>(scene)].nodes;
    } else if (nodeCount > 0) {
      std::vector<bool> isChild(nodeCount, false);
      for (const tinygltf::Node& node : mModel.nodes)
        for (int child : node.children)
          if (child >= 0 && static_cast<std::size_t>(child) < nodeCount)
            isChild[static_cast<std::size_t>(child)] = true;
      for (std::size_t n = 0; n < nodeCount; ++n)
        if (!isChild[n]) roots.push_back(static_cast<int>(n));
    } else {
      for (std::size_t m = 0; m < mModel.meshes.size(); ++m)
        if (Status placed = placeMesh(static_cast<int>(m), Transform::Identity()); !placed) return placed;
      return Ok{};
    }

    // glTF gives a node one parent at most: a node reached twice is a cycle or a shared child, and
    // either could multiply the work without end.
    struct Visit {
      int node;
      Transform parent;
    };
    std::vector<Visit> stack;
    std::vector<bool> reached(nodeCount, false);
    for (auto it = roots.rbegin(); it != roots.rend(); ++it)
      stack.push_back({*it, Transform::Identity()});
    while (!stack.empty()) {
      const Visit visit = stack.back();
      stack.pop_back();
      if (visit.node < 0 || static_cast<std::size_t>(visit.node) >= nodeCount)
        return fileError(mPath, ErrorCode::kIndexOutOfRange,
                         "node " + std::to_string(visit.node) + " does not exist (" +
                             std::to_string(nodeCount) + " nodes)");
      const auto n = static_cast<std::size_t>(visit.node);
      if (reached[n])
        return parseError("node " + std::to_string(n) +
                          " is reached twice in the scene (a cycle, or a child of two parents)");
      reached[n] = true;
      const tinygltf::Node& node = mModel.nodes[n];
      Result<Transform> local = localTransform(node, n);
      if (!local) return local.error();
      const Transform world = visit.parent * *local;
      if (node.mesh >= 0) {
        if (node.extensions.count("EXT_mesh_gpu_instancing") > 0)
          return parseError(
              "node " + std::to_string(n) +
              " places its mesh by GPU instancing (EXT_mesh_gpu_instancing), which shapedb does "
              "not read: export the instances as nodes");
        if (node.skin >= 0) ++mReport.skinnedInstances;
        if (Status placed = placeMesh(node.mesh, world); !placed) return placed;
      }
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
        stack.push_back({*c, world});
    }
    return Ok{};
  }

  Result<Transform> localTransform(const tinygltf::Node& node, std::size_t n) const {
    Transform local = Transform::Identity();
    if (node.matrix.size() == 16) {
      for (int i = 0; i < 16; ++i)
        local(i % 4, i / 4) = node.matrix[static_cast<std::size_t>(i)];  // column-major
    } else {
      Eigen::Affine3d trs = Eigen::Affine3d::Identity();
      if (node.translation.size() == 3)
        trs.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
      if (node.rotation.size() == 4) {
        Eigen::Quaterniond q(node.rotation[3], node.rotation[0], node.rotation[1],
                             node.rotation[2]);  // x y z w
        if (!(q.norm() > 0.0))
          return parseError("node " + std::to_string(n) + " has a zero rotation quaternion");
        trs.rotate(q.normalized());
      }
      if (node.scale.size() == 3) trs.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
      local = trs.matrix();
    }
    if (!local.allFinite())
      return fileError(mPath, ErrorCode::kNonFinite,
                       "node " + std::to_string(n) + " has a non-finite transform");
    return local;
  }

  // An accessor's values, components in a row, as doubles: checked against its buffer view and buffer,
  // then read (zeros where it has no buffer view), then its sparse substitutions applied.
  Result<std::vector<double>> readAccessor(int index, int type, const std::string& where,
                                           const char* what) const {
    const std::string name = where + ": " + what + " accessor " + std::to_string(index);
    if (index < 0 || static_cast<std::size_t>(index) >= mModel.accessors.size())
      return fileError(mPath, ErrorCode::kIndexOutOfRange,
                       name + " does not exist (" + std::to_string(mModel.accessors.size()) + " accessors)");
    const tinygltf::Accessor& a = mModel.accessors[static_cast<std::size_t>(index)];
    if (a.type != type)
      return parseError(name + " has the wrong type (" + (type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "SCALAR") +
                        " expected)");
    const int bytes = componentBytes(a.componentType);
    if (bytes == 0)
      return parseError(name + " has an unknown component type " + std::to_string(a.componentType));
    const std::size_t width = type == TINYGLTF_TYPE_VEC3 ? 3 : 1;
    const std::size_t element = width * static_cast<std::size_t>(bytes);
    // The count is the file's word: bound it by the bytes that could hold it before allocating.
    std::vector<double> values;
    if (a.bufferView >= 0) {
      Result<const unsigned char*> data = viewBytes(a.bufferView, a.byteOffset, a.count, element, name);
      if (!data) return data.error();
      const tinygltf::BufferView& view = mModel.bufferViews[static_cast<std::size_t>(a.bufferView)];
      const std::size_t stride = view.byteStride == 0 ? element : view.byteStride;
      values.resize(a.count * width);
      for (std::size_t i = 0; i < a.count; ++i)
        for (std::size_t c = 0; c < width; ++c)
          values[i * width + c] = readComponent(*data + i * stride + c * static_cast<std::size_t>(bytes),
                                                a.componentType, a.normalized);
    } else {
      if (!a.sparse.isSparse) return parseError(name + " has neither a buffer view nor sparse values");
      if (a.count > kMaxUnbackedElements)
        return parseError(name + " claims " + std::to_string(a.count) +
                          " elements with no buffer to hold them");
      values.assign(a.count * width, 0.0);
    }
    if (a.sparse.isSparse) {
      if (a.sparse.count < 0 || static_cast<std::size_t>(a.sparse.count) > a.count)
        return parseError(name + " has a sparse count out of range");
      const auto count = static_cast<std::size_t>(a.sparse.count);
      const int indexBytes = componentBytes(a.sparse.indices.componentType);
      const int indexType = a.sparse.indices.componentType;
      if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
          indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        return parseError(name + "'s sparse indices must be unsigned integers");
      Result<const unsigned char*> at = viewBytes(
          a.sparse.indices.bufferView, static_cast<std::size_t>(std::max(a.sparse.indices.byteOffset, 0)),
          count, static_cast<std::size_t>(indexBytes), name + "'s sparse indices");
      if (!at) return at.error();
      Result<const unsigned char*> sparseValues = viewBytes(
          a.sparse.values.bufferView, static_cast<std::size_t>(std::max(a.sparse.values.byteOffset, 0)),
          count, element, name + "'s sparse values");
      if (!sparseValues) return sparseValues.error();
      for (std::size_t s = 0; s < count; ++s) {
        const double target = readComponent(*at + s * static_cast<std::size_t>(indexBytes),
                                            a.sparse.indices.componentType, false);
        if (!(target < static_cast<double>(a.count)))
          return fileError(mPath, ErrorCode::kIndexOutOfRange, name + " has a sparse index out of range");
        const auto i = static_cast<std::size_t>(target);
        for (std::size_t c = 0; c < width; ++c)
          values[i * width + c] =
              readComponent(*sparseValues + s * element + c * static_cast<std::size_t>(bytes),
                            a.componentType, a.normalized);
      }
    }
    return values;
  }

  // The first byte of `count` elements of `element` bytes at `offset` in buffer view `index`, once they
  // are known to lie within it (at the view's stride) and the view within its buffer.
  Result<const unsigned char*> viewBytes(int index, std::size_t offset, std::size_t count,
                                         std::size_t element, const std::string& name) const {
    if (index < 0 || static_cast<std::size_t>(index) >= mModel.bufferViews.size())
      return fileError(mPath, ErrorCode::kIndexOutOfRange,
                       name + ": buffer view " + std::to_string(index) + " does not exist");
    const tinygltf::BufferView& view = mModel.bufferViews[static_cast<std::size_t>(index)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= mModel.buffers.size())
      return fileError(mPath, ErrorCode::kIndexOutOfRange,
                       name + ": buffer " + std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& buffer = mModel.buffers[static_cast<std::size_t>(view.buffer)].data;
    if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
      return parseError(name + ": buffer view " + std::to_string(index) + " (bytes " +
                        std::to_string(view.byteOffset) + " to " +
                        std::to_string(view.byteOffset + view.byteLength) + ") runs past its buffer of " +
                        std::to_string(buffer.size()) + " bytes");
    const std::size_t stride = view.byteStride == 0 ? element : view.byteStride;
    if (stride < element)
      return parseError(name + ": a stride of " + std::to_string(stride) + " bytes overlaps its elements");
    if (count > 0) {
      const std::size_t available = view.byteLength >= offset ? view.byteLength - offset : 0;
      if (available < element || (count - 1) > (available - element) / stride)
        return parseError(name + ": " + std::to_string(count) + " elements do not fit buffer view " +
                          std::to_string(index) + " (" + std::to_string(view.byteLength) + " bytes)");
    }
    return buffer.data() + view.byteOffset + offset;
  }

  Status placeMesh(int index, const Transform& world) {
    if (index < 0 || static_cast<std::size_t>(index) >= mModel.meshes.size())
      return fileError(mPath, ErrorCode::kIndexOutOfRange,
                       "mesh " + std::to_string(index) + " does not exist (" +
                           std::to_string(mModel.meshes.size()) + " meshes)");
    ++mReport.meshInstances;
    const bool mirrored = world.topLeftCorner<3, 3>().determinant() < 0.0;
    std::map<int, std::uint32_t> firstVertexOf;  // POSITION accessor → its vertices' first index, this node
    const tinygltf::Mesh& mesh = mModel.meshes[static_cast<std::size_t>(index)];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& primitive = mesh.primitives[p];
      const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        ++mReport.primitivesSkipped;
        continue;
      }
      const std::string where = "mesh " + std::to_string(index) + " primitive " + std::to_string(p);
      const auto position = primitive.attributes.find("POSITION");
      if (position == primitive.attributes.end()) return parseError(where + " has no POSITION");
      std::uint32_t first = 0;
      std::size_t vertexCount = 0;
      if (const auto known = firstVertexOf.find(position->second); known != firstVertexOf.end()) {
        first = known->second;
        vertexCount = mModel.accessors[static_cast<std::size_t>(position->second)].count;
      } else {
        Result<std::vector<double>> xyz =
            readAccessor(position->second, TINYGLTF_TYPE_VEC3, where, "POSITION");
        if (!xyz) return xyz.error();
        vertexCount = xyz->size() / 3;
        if (mRaw.vertices.size() + vertexCount > RawPolygons::kInvalidIndex)
          return parseError("more vertices than 32-bit indices can number");
        first = static_cast<std::uint32_t>(mRaw.vertices.size());
        firstVertexOf.emplace(position->second, first);
        for (std::size_t v = 0; v < vertexCount; ++v) {
          const Eigen::Vector4d local((*xyz)[3 * v], (*xyz)[3 * v + 1], (*xyz)[3 * v + 2], 1.0);
          const Eigen::Vector3d p3 = (world * local).head<3>();
          if (!p3.allFinite())
            return fileError(mPath, ErrorCode::kNonFinite,
                             where + ": vertex " + std::to_string(v) + " is not finite");
          mRaw.vertices.push_back(p3);
        }
      }
      std::vector<double> order;
      if (primitive.indices >= 0) {
        Result<std::vector<double>> indices =
            readAccessor(primitive.indices, TINYGLTF_TYPE_SCALAR, where, "index");
        if (!indices) return indices.error();
        const int type = mModel.accessors[static_cast<std::size_t>(primitive.indices)].componentType;
        if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
          return parseError(where + ": indices must be unsigned integers");
        order = std::move(indices).value();
      } else {
        order.resize(vertexCount);
        for (std::size_t v = 0; v < vertexCount; ++v)
          order[v] = static_cast<double>(v);
      }
      for (std::size_t k = 0; k < order.size(); ++k)
        if (!(order[k] < static_cast<double>(vertexCount)))
          return fileError(mPath, ErrorCode::kIndexOutOfRange,
                           where + ": index " + std::to_string(static_cast<std::uint64_t>(order[k])) +
                               " (at " + std::to_string(k) + ") is past its " + std::to_string(vertexCount) +
                               " vertices");
      if (mode == TINYGLTF_MODE_TRIANGLES && order.size() % 3 != 0)
        return parseError(where + ": " + std::to_string(order.size()) +
                          " corners, not a whole number of triangles");
      addTriangles(order, mode, first, mirrored);
    }
    return Ok{};
  }

  void addTriangles(const std::vector<double>& order, int mode, std::uint32_t first, bool mirrored) {
    const auto at = [&](std::size_t k) { return first + static_cast<std::uint32_t>(order[k]); };
    const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, bool skipRepeated) {
      if (skipRepeated && (a == b || b == c || a == c)) return;
      if (mirrored) std::swap(b, c);
      mRaw.corners.insert(mRaw.corners.end(), {a, b, c});
      mRaw.endPolygon();
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (std::size_t k = 0; k + 2 < order.size(); k += 3)
        add(at(k), at(k + 1), at(k + 2), false);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t k = 0; k + 2 < order.size(); ++k)
        if (k % 2 == 0)
          add(at(k), at(k + 1), at(k + 2), true);
        else
          add(at(k + 1), at(k), at(k + 2), true);
    } else {  // fan
      for (std::size_t k = 1; k + 1 < order.size(); ++k)
        add(at(k), at(k + 1), at(0), true);
    }
  }

  const std::filesystem::path& mPath;
  const tinygltf::Model& mModel;
  RawPolygons mRaw;
  GltfReport mReport;
};

}  // namespace

Result<RawPolygons> readGltf(const std::filesystem::path& path, GltfReport* report) {
  tinygltf::Model model;
  std::string err, warn;
  bool parsed = false;
  try {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keepImageUndecoded, nullptr);
    loader.SetFsCallbacks({regularFileExists, pathAsIs, readRegularFile, writeNothing, nullptr});
    parsed = lowercaseExtension(path) == "glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, path.string())
                                               : loader.LoadASCIIFromFile(&model, &err, &warn, path.string());
  } catch (const std::exception& e) {
    return fileError(path, ErrorCode::kParse, std::string("glTF parse error: ") + e.what());
  }
  if (!parsed) {
    // One line of printable text: the JSON parser quotes what it last read, bytes of a binary file too.
    while (!err.empty() && (err.back() == '\n' || err.back() == ' '))
      err.pop_back();
    for (char& c : err)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e)
        c = c == '\n' ? ' ' : '?';
    return fileError(path, ErrorCode::kParse,
                     "not a valid glTF file: " + (err.empty() ? std::string("unreadable") : err));
  }
  GltfReport local;
  Result<RawPolygons> raw = Reader(path, model).read(local);
  if (raw && report) *report = local;
  return raw;
}

Status writeGltf(const core::TriangleMesh& mesh, const std::filesystem::path& path) {
  const core::Bounds bounds = core::computeBounds(mesh);
  const core::Vec3 centre = 0.5 * (bounds.min + bounds.max);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "shapedb";
  tinygltf::Buffer buffer;
  const auto append = [&buffer](const auto& value) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    buffer.data.insert(buffer.data.end(), bytes, bytes + sizeof value);
  };
  tinygltf::Accessor positions;
  positions.bufferView = 0;
  positions.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  positions.type = TINYGLTF_TYPE_VEC3;
  positions.count = mesh.vertices.size();
  // glTF wants the positions' bounds exactly as stored: kept in float.
  std::array<float, 3> lo, hi;
  lo.fill(std::numeric_limits<float>::infinity());
  hi.fill(-std::numeric_limits<float>::infinity());
  for (const core::Vec3& p : mesh.vertices)
    for (std::size_t c = 0; c < 3; ++c) {
      const auto x =
          static_cast<float>(p[static_cast<Eigen::Index>(c)] - centre[static_cast<Eigen::Index>(c)]);
      append(x);
      lo[c] = std::min(lo[c], x);
      hi[c] = std::max(hi[c], x);
    }
  positions.minValues.assign(lo.begin(), lo.end());
  positions.maxValues.assign(hi.begin(), hi.end());
  const std::size_t positionBytes = buffer.data.size();
  for (const auto& t : mesh.triangles)
    for (const std::uint32_t v : t)
      append(v);
  tinygltf::BufferView positionView, indexView;
  positionView.buffer = indexView.buffer = 0;
  positionView.byteLength = positionBytes;
  positionView.target = TINYGLTF_TARGET_ARRAY_BUFFER;
  indexView.byteOffset = positionBytes;
  indexView.byteLength = buffer.data.size() - positionBytes;
  indexView.target = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
  tinygltf::Accessor indices;
  indices.bufferView = 1;
  indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  indices.type = TINYGLTF_TYPE_SCALAR;
  indices.count = 3 * mesh.triangles.size();
  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = 0;
  primitive.indices = 1;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh gltfMesh;
  gltfMesh.primitives.push_back(primitive);
  tinygltf::Node node;
  node.mesh = 0;
  node.translation = {centre.x(), centre.y(), centre.z()};
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.buffers.push_back(std::move(buffer));
  model.bufferViews = {positionView, indexView};
  model.accessors = {positions, indices};
  model.meshes.push_back(std::move(gltfMesh));
  model.nodes.push_back(std::move(node));
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;

  bool written = false;
  try {
    tinygltf::TinyGLTF writer;
    const bool binary = lowercaseExtension(path) == "glb";
    written = writer.WriteGltfSceneToFile(&model, path.string(), false, true, !binary, binary);
  } catch (const std::exception& e) {
    return fileError(path, ErrorCode::kIo, std::string("cannot write glTF: ") + e.what());
  }
  if (!written) return fileError(path, ErrorCode::kIo, "cannot write file");
  return Ok{};
}

}  // namespace shapedb::io::detail
