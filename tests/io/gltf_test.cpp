// glTF 2.0 files, written by tinygltf's own writer (tests/support/mesh_files.h) and read by loadMesh:
// round trips, the scene's transforms, the ways a surface may be cut into primitives, and broken files.

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "io/load_checks.h"
#include "support/mesh_files.h"
#include "support/test_support.h"

namespace shapedb::io::gltf_test {
namespace {

using core::TriangleMesh;
using core::Vec3;

using test_checks::mustFail;
using test_checks::mustLoad;
using test_checks::volumeOf;

// A point as glTF stores it: every coordinate rounded to single precision. Through memory: GCC 12's
// vectorizer at -O2 takes a pair of double → float → double conversions for no-ops.
Vec3 inFloats(const Vec3& p) {
  volatile float x = static_cast<float>(p.x()), y = static_cast<float>(p.y()), z = static_cast<float>(p.z());
  return {x, y, z};
}

TriangleMesh inFloats(TriangleMesh mesh) {
  for (Vec3& p : mesh.vertices)
    p = inFloats(p);
  return mesh;
}

TEST(Gltf, ASurfaceReadsBackFromGlbAndFromGltfWithEmbeddedOrExternalBuffers) {
  test::ScratchDir dir("gltf");
  const TriangleMesh blob = test::makeLopsidedBlob({0.05, 0.08, 0.035}, 3);
  const TriangleMesh expected = inFloats(blob);
  const tinygltf::Model model = test::gltfOf(blob);
  ASSERT_TRUE(test::writeGltf(model, dir / "blob.glb"));
  ASSERT_TRUE(test::writeGltf(model, dir / "embedded.gltf", true));
  ASSERT_TRUE(test::writeGltf(model, dir / "external.gltf", false));
  ASSERT_TRUE(std::filesystem::exists(dir / "external.bin"));
  for (const char* name : {"blob.glb", "embedded.gltf", "external.gltf"}) {
    SCOPED_TRACE(name);
    const LoadedMesh loaded = mustLoad(dir / name);
    EXPECT_EQ(loaded.format, std::filesystem::path(name).extension().string().substr(1));
    EXPECT_EQ(loaded.mesh.triangles, blob.triangles);
    ASSERT_EQ(loaded.mesh.vertices.size(), blob.vertices.size());
    EXPECT_EQ(test::maxVertexDifference(loaded.mesh, expected), 0.0);
    EXPECT_TRUE(loaded.topology.isClosed());
    EXPECT_EQ(loaded.meshInstances, 1u);
    EXPECT_TRUE(loaded.notes().empty());
    EXPECT_NEAR(volumeOf(loaded.mesh), volumeOf(blob), 1e-6 * volumeOf(blob));
  }
}

TEST(Gltf, NodesPlaceTheMeshThroughTheirTransforms) {
  test::ScratchDir dir("gltf");
  const TriangleMesh box = core::makeBox({0.3, 0.2, 0.1});
  tinygltf::Model model = test::gltfOf(box);
  // A parent (a matrix: scale 2, moved) holding the mesh's node (translation, rotation, scale).
  Eigen::Affine3d parent = Eigen::Affine3d::Identity();
  parent.translate(Vec3(10.0, -4.0, 0.5)).scale(2.0);
  tinygltf::Node root;
  root.children = {1};
  root.matrix.assign(parent.matrix().data(), parent.matrix().data() + 16);  // column-major, as glTF's
  tinygltf::Node child = model.nodes[0];
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Vec3(1.0, 2.0, -0.5).normalized()));
  child.translation = {0.25, 0.5, -1.0};
  child.rotation = {q.x(), q.y(), q.z(), q.w()};
  child.scale = {1.0, 3.0, 0.5};
  model.nodes = {root, child};
  model.scenes[0].nodes = {0};
  ASSERT_TRUE(test::writeGltf(model, dir / "placed.glb"));

  const LoadedMesh loaded = mustLoad(dir / "placed.glb");
  Eigen::Affine3d local = Eigen::Affine3d::Identity();
  local.translate(Vec3(0.25, 0.5, -1.0)).rotate(q).scale(Vec3(1.0, 3.0, 0.5));
  const Eigen::Affine3d world = parent * local;
  ASSERT_EQ(loaded.mesh.vertices.size(), box.vertices.size());
  for (std::size_t v = 0; v < box.vertices.size(); ++v)
    EXPECT_LT((loaded.mesh.vertices[v] - world * inFloats(box.vertices[v])).norm(), 1e-12) << "vertex " << v;
  EXPECT_NEAR(volumeOf(loaded.mesh), 0.006 * 8.0 * 1.5, 1e-6 * 0.072);  // the box in floats
  EXPECT_FALSE(loaded.flippedInsideOut);
}

TEST(Gltf, AMirroringTransformKeepsTheSurfaceWoundOutward) {
  test::ScratchDir dir("gltf");
  tinygltf::Model model = test::gltfOf(core::makeBox({0.3, 0.2, 0.1}));
  model.nodes[0].scale = {-1.0, 1.0, 1.0};
  ASSERT_TRUE(test::writeGltf(model, dir / "mirrored.glb"));
  const LoadedMesh loaded = mustLoad(dir / "mirrored.glb");
  // Rewound as it was placed, not flipped afterwards as an inside-out file would be.
  EXPECT_FALSE(loaded.flippedInsideOut);
  EXPECT_GT(loaded.signedVolumeAsRead, 0.0);
  EXPECT_NEAR(volumeOf(loaded.mesh), 0.006, 1e-6 * 0.006);
}

TEST(Gltf, PrimitivesOfOneSurfaceShareTheirPositionsOrAreWeldedAlongTheirSeams) {
  test::ScratchDir dir("gltf");
  const TriangleMesh blob = test::makeLopsidedBlob({0.05, 0.08, 0.035}, 2);
  const std::size_t half = blob.triangles.size() / 2;

  // Two primitives (two materials, say) over one POSITION accessor: one surface, nothing to weld.
  tinygltf::Model shared = test::gltfOf(blob);
  tinygltf::Accessor second = shared.accessors[1];
  shared.accessors[1].count = 3 * half;
  second.byteOffset = 3 * half * 4;
  second.count = 3 * (blob.triangles.size() - half);
  shared.accessors.push_back(second);
  tinygltf::Primitive other = shared.meshes[0].primitives[0];
  other.indices = 2;
  shared.meshes[0].primitives.push_back(other);
  ASSERT_TRUE(test::writeGltf(shared, dir / "shared.glb"));
  const LoadedMesh one = mustLoad(dir / "shared.glb");
  EXPECT_EQ(one.mesh.vertices.size(), blob.vertices.size());
  EXPECT_EQ(one.mesh.triangles, blob.triangles);
  EXPECT_EQ(one.verticesWelded, 0u);
  EXPECT_TRUE(one.topology.isClosed());

  // Two meshes' worth of vertices, as exporters split a surface at material seams: welded back.
  TriangleMesh first = blob, rest = blob;
  first.triangles.resize(half);
  rest.triangles.erase(rest.triangles.begin(), rest.triangles.begin() + static_cast<std::ptrdiff_t>(half));
  tinygltf::Model split = test::gltfOf(first);
  const tinygltf::Model restModel = test::gltfOf(rest);
  tinygltf::Buffer& buffer = split.buffers[0];
  const std::size_t offset = buffer.data.size();
  buffer.data.insert(buffer.data.end(), restModel.buffers[0].data.begin(), restModel.buffers[0].data.end());
  for (tinygltf::BufferView view : restModel.bufferViews) {
    view.byteOffset += offset;
    split.bufferViews.push_back(view);
  }
  for (tinygltf::Accessor accessor : restModel.accessors) {
    accessor.bufferView += 2;
    split.accessors.push_back(accessor);
  }
  tinygltf::Primitive restPrimitive;
  restPrimitive.attributes["POSITION"] = 2;
  restPrimitive.indices = 3;
  restPrimitive.mode = TINYGLTF_MODE_TRIANGLES;
  split.meshes[0].primitives.push_back(restPrimitive);
  ASSERT_TRUE(test::writeGltf(split, dir / "split.glb"));
  const LoadedMesh welded = mustLoad(dir / "split.glb");
  EXPECT_TRUE(welded.topology.isClosed());
  EXPECT_EQ(welded.verticesWelded, blob.vertices.size());
  EXPECT_EQ(welded.mesh.triangles.size(), blob.triangles.size());
  EXPECT_NEAR(volumeOf(welded.mesh), volumeOf(blob), 1e-6 * volumeOf(blob));
}

TEST(Gltf, StripsAndFansAreTriangulatedKeepingTheirWinding) {
  test::ScratchDir dir("gltf");
  // Two unit squares in the plane z = 0, apart, wound to face +z: as one strip with a degenerate join,
  // and as a fan each.
  TriangleMesh squares;
  squares.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}, {3, 0, 0}, {2, 1, 0}, {3, 1, 0}};
  for (const auto& [name, mode, order] :
       {std::tuple{"strip", TINYGLTF_MODE_TRIANGLE_STRIP,
                   std::vector<std::uint32_t>{0, 1, 2, 3, 3, 4, 4, 5, 6, 7}},
        std::tuple{"fan", TINYGLTF_MODE_TRIANGLE_FAN, std::vector<std::uint32_t>{0, 1, 3, 2}}}) {
    SCOPED_TRACE(name);
    TriangleMesh carrier = squares;  // gltfOf writes triangles' corners; the order replaces them
    carrier.triangles.clear();
    for (std::size_t k = 0; k + 2 < order.size(); k += 3)
      carrier.triangles.push_back({order[k], order[k + 1], order[k + 2]});
    tinygltf::Model model = test::gltfOf(carrier);
    tinygltf::Buffer& buffer = model.buffers[0];
    buffer.data.resize(model.bufferViews[1].byteOffset);
    for (const std::uint32_t v : order) {
      const auto* bytes = reinterpret_cast<const unsigned char*>(&v);
      buffer.data.insert(buffer.data.end(), bytes, bytes + 4);
    }
    model.bufferViews[1].byteLength = 4 * order.size();
    model.accessors[1].count = order.size();
    model.meshes[0].primitives[0].mode = mode;
    const std::filesystem::path path = dir / (std::string(name) + ".glb");
    ASSERT_TRUE(test::writeGltf(model, path));
    const LoadedMesh loaded = mustLoad(path);
    const std::size_t expectedTriangles = mode == TINYGLTF_MODE_TRIANGLE_STRIP ? 4 : 2;
    ASSERT_EQ(loaded.mesh.triangles.size(), expectedTriangles);
    double area = 0.0;
    for (const auto& t : loaded.mesh.triangles) {
      const Vec3 n = (loaded.mesh.vertices[t[1]] - loaded.mesh.vertices[t[0]])
                         .cross(loaded.mesh.vertices[t[2]] - loaded.mesh.vertices[t[0]]);
      EXPECT_GT(n.z(), 0.0);
      area += 0.5 * n.norm();
    }
    EXPECT_DOUBLE_EQ(area, mode == TINYGLTF_MODE_TRIANGLE_STRIP ? 2.0 : 1.0);
  }
}

TEST(Gltf, QuantizedAndSparsePositionsAreReadAsGltfDefinesThem) {
  test::ScratchDir dir("gltf");
  const TriangleMesh unit = core::makeBox({1.0, 1.0, 1.0});  // corners at ±0.5
  // KHR_mesh_quantization: positions as normalized unsigned shorts in [0, 1], the node scaling them.
  tinygltf::Model model = test::gltfOf(unit);
  std::vector<unsigned char> quantized;
  for (const Vec3& p : unit.vertices)
    for (int c = 0; c < 4; ++c) {  // each element padded to 8 bytes, as glTF aligns vertex attributes
      const std::uint16_t q = c < 3 && p[c] > 0.0 ? 65535 : 0;
      quantized.push_back(static_cast<unsigned char>(q & 0xff));
      quantized.push_back(static_cast<unsigned char>(q >> 8));
    }
  std::vector<unsigned char>& data = model.buffers[0].data;
  const std::vector<unsigned char> indices(
      data.begin() + static_cast<std::ptrdiff_t>(model.bufferViews[1].byteOffset), data.end());
  data = quantized;
  data.insert(data.end(), indices.begin(), indices.end());
  model.bufferViews[0].byteLength = quantized.size();
  model.bufferViews[0].byteStride = 8;
  model.bufferViews[1].byteOffset = quantized.size();
  model.accessors[0].componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
  model.accessors[0].normalized = true;
  model.accessors[0].minValues = {0, 0, 0};
  model.accessors[0].maxValues = {1, 1, 1};
  model.extensionsUsed = model.extensionsRequired = {"KHR_mesh_quantization"};
  model.nodes[0].scale = {0.3, 0.2, 0.1};
  ASSERT_TRUE(test::writeGltf(model, dir / "quantized.glb"));
  const LoadedMesh loaded = mustLoad(dir / "quantized.glb");
  ASSERT_EQ(loaded.mesh.vertices.size(), unit.vertices.size());
  for (std::size_t v = 0; v < unit.vertices.size(); ++v) {
    const Vec3 expected = (unit.vertices[v] + Vec3::Constant(0.5)).cwiseProduct(Vec3(0.3, 0.2, 0.1));
    EXPECT_LT((loaded.mesh.vertices[v] - expected).norm(), 1e-15) << "vertex " << v;
  }
  EXPECT_NEAR(volumeOf(loaded.mesh), 0.006, 1e-12);

  // A sparse accessor: vertex 0 of the float positions replaced by one twice as far out.
  tinygltf::Model sparse = test::gltfOf(unit);
  std::vector<unsigned char>& bytes = sparse.buffers[0].data;
  const std::size_t at = bytes.size();
  const std::uint32_t target = 0;
  const std::array<float, 3> moved{static_cast<float>(2 * unit.vertices[0].x()),
                                   static_cast<float>(2 * unit.vertices[0].y()),
                                   static_cast<float>(2 * unit.vertices[0].z())};
  bytes.insert(bytes.end(), reinterpret_cast<const unsigned char*>(&target),
               reinterpret_cast<const unsigned char*>(&target) + 4);
  bytes.insert(bytes.end(), reinterpret_cast<const unsigned char*>(moved.data()),
               reinterpret_cast<const unsigned char*>(moved.data()) + 12);
  tinygltf::BufferView indexView, valueView;
  indexView.buffer = valueView.buffer = 0;
  indexView.byteOffset = at;
  indexView.byteLength = 4;
  valueView.byteOffset = at + 4;
  valueView.byteLength = 12;
  sparse.bufferViews.push_back(indexView);
  sparse.bufferViews.push_back(valueView);
  tinygltf::Accessor& positions = sparse.accessors[0];
  positions.sparse.isSparse = true;
  positions.sparse.count = 1;
  positions.sparse.indices = {0, 2, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT};
  positions.sparse.values = {3, 0};
  for (int c = 0; c < 3; ++c) {
    positions.minValues[static_cast<std::size_t>(c)] = std::min<double>(
        positions.minValues[static_cast<std::size_t>(c)], moved[static_cast<std::size_t>(c)]);
    positions.maxValues[static_cast<std::size_t>(c)] = std::max<double>(
        positions.maxValues[static_cast<std::size_t>(c)], moved[static_cast<std::size_t>(c)]);
  }
  ASSERT_TRUE(test::writeGltf(sparse, dir / "sparse.glb"));
  const LoadedMesh substituted = mustLoad(dir / "sparse.glb");
  ASSERT_EQ(substituted.mesh.vertices.size(), unit.vertices.size());
  EXPECT_EQ(substituted.mesh.vertices[0], 2.0 * unit.vertices[0]);
  for (std::size_t v = 1; v < unit.vertices.size(); ++v)
    EXPECT_EQ(substituted.mesh.vertices[v], unit.vertices[v]);
}

TEST(Gltf, AMeshPlacedTwiceIsTwoSolidsAndItsSizeCountsBoth) {
  test::ScratchDir dir("gltf");
  const TriangleMesh box = core::makeBox({0.3, 0.2, 0.1});
  tinygltf::Model model = test::gltfOf(box);
  tinygltf::Node again = model.nodes[0];
  again.translation = {1.0, 0.0, 0.0};
  model.nodes.push_back(again);
  model.scenes[0].nodes = {0, 1};
  ASSERT_TRUE(test::writeGltf(model, dir / "pair.gltf"));
  const LoadedMesh loaded = mustLoad(dir / "pair.gltf");
  EXPECT_EQ(loaded.meshInstances, 2u);
  EXPECT_EQ(loaded.mesh.vertices.size(), 2 * box.vertices.size());
  EXPECT_EQ(loaded.topology.components, 2u);
  ASSERT_EQ(loaded.notes().size(), 1u);
  EXPECT_NE(loaded.notes()[0].find("places 2 meshes"), std::string::npos) << loaded.notes()[0];

  for (const char* name : {"pair.gltf", "pair.glb"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(test::writeGltf(model, dir / name));
    const Result<MeshFileSize> size = estimateMeshFile(dir / name);
    ASSERT_TRUE(size.ok()) << size.error().message;
    EXPECT_EQ(size->triangles, 2 * box.triangles.size());
    EXPECT_EQ(size->vertices, 2 * box.vertices.size());
  }
}

TEST(Gltf, SaveMeshWritesGlbAndGltfThatReadBackAboutTheMeshsCentre) {
  test::ScratchDir dir("gltf");
  // A fragment as a scan's would be, hundreds of kilometres from the origin: stored about its centre,
  // it keeps single precision at its own size (a float of its coordinates would move it by centimetres).
  TriangleMesh far = test::makeLopsidedBlob({0.05, 0.08, 0.035}, 3);
  for (Vec3& p : far.vertices)
    p += Vec3(6.4e5, -1.3e6, 0.1);
  for (const char* name : {"far.glb", "far.gltf"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(saveMesh(far, dir / name).ok());
    const LoadedMesh loaded = mustLoad(dir / name);
    EXPECT_EQ(loaded.mesh.triangles, far.triangles);
    EXPECT_TRUE(loaded.topology.isClosed());
    EXPECT_TRUE(loaded.notes().empty());
    EXPECT_LT(test::maxVertexDifference(loaded.mesh, far), 1e-8) << "metres";
    EXPECT_NEAR(volumeOf(loaded.mesh), volumeOf(far), 1e-6 * volumeOf(far));
  }
  // One file, whatever the extension's case; nothing beside it.
  EXPECT_EQ(
      std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()),
      2);
  EXPECT_EQ(saveMesh(far, dir / "far.fbx").error().code, ErrorCode::kUnknownFormat);
}

TEST(Gltf, BrokenFilesAreRefusedWithTheirReason) {
  test::ScratchDir dir("gltf");
  const tinygltf::Model good = test::gltfOf(core::makeBox({0.3, 0.2, 0.1}));
  struct Case {
    const char* name;
    std::function<void(tinygltf::Model&)> breakIt;
    ErrorCode code;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"count_past_view.glb", [](tinygltf::Model& m) { m.accessors[0].count = 1000; }, ErrorCode::kParse,
       "do not fit buffer view"},
      {"view_past_buffer.glb", [](tinygltf::Model& m) { m.bufferViews[1].byteLength += 64; },
       ErrorCode::kParse, "runs past its buffer"},
      {"index_past_vertices.glb",
       [](tinygltf::Model& m) {
         const std::uint32_t big = 4000;
         std::memcpy(m.buffers[0].data.data() + m.bufferViews[1].byteOffset + 8, &big, 4);
       },
       ErrorCode::kIndexOutOfRange, "is past its 8 vertices"},
      {"cycle.glb", [](tinygltf::Model& m) { m.nodes[0].children = {0}; }, ErrorCode::kParse,
       "reached twice"},
      {"draco.glb",
       [](tinygltf::Model& m) { m.extensionsUsed = m.extensionsRequired = {"KHR_draco_mesh_compression"}; },
       ErrorCode::kParse, "compressed (KHR_draco_mesh_compression)"},
      {"signed_sparse_indices.glb",
       [](tinygltf::Model& m) {
         m.accessors[0].sparse.isSparse = true;
         m.accessors[0].sparse.count = 1;
         m.accessors[0].sparse.indices = {0, 1, TINYGLTF_COMPONENT_TYPE_BYTE};
         m.accessors[0].sparse.values = {0, 0};
       },
       ErrorCode::kParse, "sparse indices must be unsigned integers"},
      {"lines.glb", [](tinygltf::Model& m) { m.meshes[0].primitives[0].mode = TINYGLTF_MODE_LINE; },
       ErrorCode::kEmptyMesh, "no triangles (1 point or line primitives)"},
      {"no_such_mesh.glb", [](tinygltf::Model& m) { m.nodes[0].mesh = 5; }, ErrorCode::kIndexOutOfRange,
       "mesh 5 does not exist"},
      {"infinite.glb",
       [](tinygltf::Model& m) {
         m.nodes[0].translation = {1.7e308, 0.0, 0.0};
         m.nodes[0].scale = {1e308, 1e308, 1e308};
       },
       ErrorCode::kNonFinite, "is not finite"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    tinygltf::Model broken = good;
    c.breakIt(broken);
    ASSERT_TRUE(test::writeGltf(broken, dir / c.name));
    const Error e = mustFail(dir / c.name);
    EXPECT_EQ(e.code, c.code) << e.message;
    EXPECT_NE(e.message.find(c.says), std::string::npos) << e.message;
  }

  // Files that are not glTF, or whose parts are missing: tinygltf's own reason.
  ASSERT_TRUE(test::writeGltf(good, dir / "external.gltf", false));
  std::filesystem::remove(dir / "external.bin");
  ASSERT_TRUE(test::writeGltf(good, dir / "whole.glb"));
  std::string glb = test::readFile(dir / "whole.glb");
  test::writeFile(dir / "truncated.glb", glb.substr(0, glb.size() / 2));
  test::writeFile(dir / "text.gltf", "this is not JSON");
  test::writeFile(dir / "empty_object.gltf", "{}");
  for (const char* name : {"external.gltf", "truncated.glb", "text.gltf", "empty_object.gltf"}) {
    SCOPED_TRACE(name);
    const Error e = mustFail(dir / name);
    EXPECT_EQ(e.code, ErrorCode::kParse) << e.message;
    EXPECT_NE(e.message.find("not a valid glTF file: "), std::string::npos) << e.message;
  }
}

TEST(Gltf, RealMeshesReadTheSameFromGlb) {
  std::string why;
  const std::optional<std::filesystem::path> real = test::realMeshDirectory(&why);
  if (!real) GTEST_SKIP() << why;
  test::ScratchDir dir("gltf");
  const Result<std::vector<std::filesystem::path>> files = listMeshFiles(*real);
  ASSERT_TRUE(files.ok()) << files.error().message;
  std::size_t read = 0;
  for (const std::filesystem::path& file : *files) {
    SCOPED_TRACE(file.string());
    const Result<LoadedMesh> original = loadMesh(file);
    if (!original) continue;  // a mesh the loader refuses is the other tests' business
    const std::filesystem::path glb = dir / (file.stem().string() + ".glb");
    ASSERT_TRUE(test::writeGltf(test::gltfOf(original->mesh), glb));
    const LoadedMesh loaded = mustLoad(glb);
    EXPECT_EQ(loaded.mesh.triangles, original->mesh.triangles);
    EXPECT_EQ(test::maxVertexDifference(loaded.mesh, inFloats(original->mesh)), 0.0);
    EXPECT_EQ(loaded.topology.isClosed(), original->topology.isClosed());
    EXPECT_EQ(loaded.topology.components, original->topology.components);
    ++read;
  }
  EXPECT_GT(read, 0u);
}

}  // namespace
}  // namespace shapedb::io::gltf_test
