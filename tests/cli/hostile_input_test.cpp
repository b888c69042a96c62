// The hostile-input corpus: malformed, lying, degenerate and extreme mesh files, each given to the real
// `shapedb query` (the whole pipeline: read, validate, mass properties, frame, descriptors, search,
// adapt, link) as a subprocess. Each must give its documented error (exit 1, the file named, the problem
// said) or its documented result (exit 0), never a crash, a hang, or unbounded memory. The table is
// docs/hostile-input.md.

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>

#include "support/mesh_files.h"
#include "support/subprocess.h"
#include "support/test_support.h"

namespace shapedb::cli {
namespace {

using core::TriangleMesh;
using core::Vec3;

const std::string kTet = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
const std::string kTetFaces = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

std::string plyHeader(const std::string& format, std::size_t vertices, std::size_t faces) {
  return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(faces) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

const std::string kPlyTetBody = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";

std::string binaryPlyTet(std::size_t claimedVertices, std::size_t claimedFaces) {
  std::string out = plyHeader("binary_little_endian", claimedVertices, claimedFaces);
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  out.append(reinterpret_cast<const char*>(v), sizeof v);
  const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  for (const auto& face : f) {
    out.push_back(3);
    out.append(reinterpret_cast<const char*>(face), sizeof face);
  }
  return out;
}

TriangleMesh scaled(TriangleMesh mesh, double s) {
  for (Vec3& p : mesh.vertices)
    p *= s;
  return mesh;
}

/// A box whose faces share no vertex: every corner repeated per triangle, as a triangle soup is.
TriangleMesh reversed(TriangleMesh mesh, std::size_t count) {
  for (std::size_t i = 0; i < count && i < mesh.triangles.size(); ++i)
    std::swap(mesh.triangles[i][1], mesh.triangles[i][2]);
  return mesh;
}

TriangleMesh merged(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out = a;
  core::append(out, b);
  return out;
}

TriangleMesh translated(TriangleMesh mesh, const Vec3& d) {
  for (Vec3& p : mesh.vertices)
    p += d;
  return mesh;
}

/// The bytes of a glTF file that tinygltf writes for `model` (a .glb, or a .gltf with its buffer embedded).
std::string gltfBytes(const tinygltf::Model& model, const char* extension) {
  const test::ScratchDir dir("hostile-gltf");
  const std::filesystem::path path = dir / (std::string("model") + extension);
  EXPECT_TRUE(test::writeGltf(model, path));
  return test::readFile(path);
}

/// What a case must give. An error: exit 1 and `message` in what is printed (the file is always
/// named). A result: exit 0 and `check` holds on the query's JSON.
struct Case {
  std::string file;  ///< name, with the extension that picks the reader
  std::function<std::string()> content;
  std::string message;  ///< empty: the query must succeed
  std::function<void(const nlohmann::json&)> check = {};
};

std::vector<Case> corpus() {
  const TriangleMesh box = core::makeBox({0.3, 0.2, 0.1});
  const TriangleMesh blob = core::makeIcosphere(0.1, 3);
  std::string garbage;
  for (int i = 0; i < 4096; ++i)
    garbage.push_back(static_cast<char>((i * 7919 + 13) % 256));
  auto massNear = [](double volume) {
    const double expected = 7850.0 * volume;
    return [expected](const nlohmann::json& q) {
      EXPECT_NEAR(q["physics"]["mass"].get<double>(), expected, 1e-5 * expected);  // steel, the default
    };
  };
  // A query answered with this among its warnings, and without a predicted error.
  auto warns = [](std::string what) {
    return [what](const nlohmann::json& q) {
      bool found = false;
      for (const auto& w : q["physics"]["warnings"])
        found = found || w.get<std::string>().find(what) != std::string::npos;
      EXPECT_TRUE(found) << "no warning with '" << what << "' in " << q["physics"]["warnings"].dump();
      EXPECT_FALSE(q.contains("predicted_frequency_error"));
    };
  };
  return {
      // Files that are not what they say.
      {"empty.obj", [] { return std::string(); }, "file is empty"},
      {"garbage.obj", [=] { return garbage; }, "no faces"},
      {"garbage.stl", [=] { return garbage; }, "binary STL"},
      {"garbage.ply", [=] { return garbage; }, "not a PLY file"},
      {"unknown.xyz", [] { return kTet + kTetFaces; }, "unknown mesh format"},
      // Binary STL: cut short, a count that lies (2³¹), none at all, or ASCII's "solid" on binary data.
      {"truncated.stl", [=] { return test::binaryStl(box).substr(0, 84 + 50 * 5 + 17); },
       "truncated or corrupt binary STL (header says 12 triangles, file holds 5)"},
      {"claims_2pow31.stl", [=] { return test::binaryStl(box, 1u << 31); },
       "header says 2147483648 triangles"},
      {"zero_triangles.stl", [=] { return test::binaryStl(TriangleMesh{}); }, "no faces"},
      {"ascii_cut_mid_facet.stl", [=] { return test::asciiStl(box).substr(0, 700); }, "not closed"},
      {"solid_header_binary.stl",
       [=] {
         std::string s = test::binaryStl(box);
         std::memcpy(s.data(), "solid box", 9);
         return s;
       },
       "", massNear(0.3 * 0.2 * 0.1)},
      // PLY whose counts lie, in both encodings, or whose header never ends.
      {"vertex_count_lies.ply", [] { return plyHeader("ascii", 100, 4) + kPlyTetBody; },
       "the header says 100 vertex items"},
      {"face_count_lies.ply", [] { return binaryPlyTet(4, 100); }, "the header says 100 face items"},
      {"claims_4g_vertices.ply", [] { return binaryPlyTet(4294967295u, 4); },
       "the header says 4294967295 vertex items"},
      {"list_count_lies.ply",
       [] {
         return plyHeader("ascii", 4, 4) +
                "0 0 0\n1 0 0\n0 1 0\n0 0 1\n255 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
       },
       "the file ends in face 0 of 4"},
      {"no_end_header.ply",
       [] { return std::string("ply\nformat ascii 1.0\nelement vertex 4\n") + kPlyTetBody; },
       "unknown PLY header line '0'"},
      {"header_never_ends.ply", [] { return std::string("ply\nformat ascii 1.0\nelement vertex 4\n"); },
       "PLY header without end_header"},
      {"face_index_out_of_range.ply",
       [] {
         return plyHeader("ascii", 4, 4) + "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 9\n";
       },
       "refers to vertex 9"},
      // OFF whose counts lie.
      {"vertex_count_lies.off", [] { return "OFF\n8 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n"; },
       "the header says 8 vertices, the file ends after 6"},
      {"binary.off", [] { return "OFF BINARY\n4 4 0\n" + std::string(64, '\0'); },
       "binary OFF is not supported"},
      // OBJ indices: negative past the start, overflowing, zero.
      {"negative_index.obj", [] { return kTet + kTetFaces + "f -1 -2 -9\n"; }, "out of range"},
      {"overflowing_index.obj",
       [] { return kTet + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 99999999999999999999\n"; }, "out of range"},
      {"zero_index.obj", [] { return kTet + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 0 4 3\n"; }, "out of range"},
      // Numbers: NaN, infinities, beyond double, beyond float, and extreme but representable sizes.
      {"nan.obj", [] { return "v 0 0 nan\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + kTetFaces; },
       "non-finite number 'nan'"},
      {"inf.off",
       [] { return "OFF\n4 4 0\n0 0 0\n1 0 -inf\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n"; },
       "non-finite number '-inf'"},
      {"beyond_double.obj", [] { return "v 0 0 1e400\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + kTetFaces; },
       "non-finite number '1e400'"},
      {"nan.ply",
       [] {
         return plyHeader("ascii", 4, 4) +
                "0 0 0\n1 0 0\n0 1 nan\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
       },
       "vertex 2 has a non-finite coordinate"},
      {"needle_1e39.obj", [] { return "v 0 0 1e39\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + kTetFaces; },
       "degenerate faces"},
      {"huge_1e38.obj", [=] { return test::objText(scaled(box, 1e38)); }, "", nullptr},
      {"tiny_1e-30.obj", [=] { return test::objText(scaled(box, 1e-30)); }, "", nullptr},
      // Faces: zero area, repeated vertices, two corners.
      {"zero_area_face.obj", [] { return kTet + "v 0.5 0 0\n" + kTetFaces + "f 1 5 2\n"; }, "degenerate"},
      // A T-junction closed by a zero-area face (a unit cube, a vertex on its bottom front edge): flipped
      // away at load, with a warning, and the cube answered whole.
      {"t_junction.obj",
       [] {
         return std::string(
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 0.5 0 0\n"
             "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 9 6\nf 1 6 5\nf 9 2 6\nf 1 2 9\nf 2 3 7\n"
             "f 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
       },
       "", massNear(1.0)},
      {"repeated_vertex_face.off",
       [] { return "OFF\n4 5 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n3 0 0 1\n"; },
       "degenerate"},
      {"two_corner_face.obj", [] { return kTet + kTetFaces + "f 1 2\n"; }, "fewer than 3 vertices"},
      {"vertices_only.obj", [] { return kTet; }, "no faces"},
      // Surfaces: open, a single triangle, coincident vertices (soup), non-manifold, coplanar, reversed.
      {"open_box.obj",
       [=] {
         TriangleMesh open = box;
         open.triangles.resize(open.triangles.size() - 2);
         return test::objText(open);
       },
       "not closed (4 boundary edges); --approximate answers it from vertex point masses (marked "
       "approximate); if its vertices only nearly coincide, --weld-tolerance"},
      {"single_triangle.obj", [] { return "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"; }, "not closed"},
      {"coincident_vertices_soup.obj", [=] { return test::objText(test::soupOf(box)); }, "",
       massNear(0.3 * 0.2 * 0.1)},  // welded at load, with a warning
      {"fin_on_a_tet.obj", [] { return kTet + "v 1 1 1\n" + kTetFaces + "f 1 2 5\n"; }, "not closed"},
      {"two_tets_sharing_an_edge.obj",
       [] { return kTet + "v 0 -1 0\nv 0 0 -1\n" + kTetFaces + "f 1 2 5\nf 1 6 2\nf 2 6 5\nf 1 5 6\n"; },
       "not manifold"},
      {"all_coplanar_two_sided.obj", [] { return "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 2\n"; },
       "volume"},
      {"inside_out.obj", [=] { return test::objText(reversed(box, box.triangles.size())); }, "",
       massNear(0.3 * 0.2 * 0.1)},  // flipped at load, with a warning
      {"one_face_flipped.obj", [=] { return test::objText(reversed(box, 1)); }, "orient"},
      // Self-intersecting and multi-part solids: documented results (signed volume; one object).
      {"self_intersecting_boxes.obj",
       [=] {
         return test::objText(merged(box, translated(box, {0.15, 0.0, 0.0})));
       },
       "", massNear(2 * 0.3 * 0.2 * 0.1)},
      {"two_separate_spheres.obj",
       [=] {
         return test::objText(merged(blob, translated(blob, {1.0, 0.0, 0.0})));
       },
       "", warns("2 closed shells wound outward")},
      // glTF: not glTF at all, an accessor whose count lies, a mesh placed twice (two solids), a box.
      {"garbage.glb", [=] { return garbage; }, "not a valid glTF file"},
      {"garbage.gltf", [=] { return garbage; }, "not a valid glTF file"},
      {"count_lies.glb",
       [=] {
         tinygltf::Model model = test::gltfOf(box);
         model.accessors[0].count = 1u << 30;
         return gltfBytes(model, ".glb");
       },
       "1073741824 elements do not fit buffer view 0"},
      {"placed_twice.gltf",
       [=] {
         tinygltf::Model model = test::gltfOf(blob);
         tinygltf::Node again = model.nodes[0];
         again.translation = {1.0, 0.0, 0.0};
         model.nodes.push_back(again);
         model.scenes[0].nodes = {0, 1};
         return gltfBytes(model, ".gltf");
       },
       "", warns("2 closed shells wound outward")},
      {"box.glb", [=] { return gltfBytes(test::gltfOf(box), ".glb"); }, "", massNear(0.3 * 0.2 * 0.1)},
      // FBX and COLLADA (read by assimp in a worker process): not those at all, a box.
      {"garbage.fbx", [=] { return garbage; }, "assimp"},
      {"garbage.dae", [=] { return garbage; }, "assimp"},
      {"box.dae", [=] { return test::colladaText(box); }, "", massNear(0.3 * 0.2 * 0.1)},
      // A scan with floating specks (a speck of a ball and a lone triangle): dropped, then answered as the
      // one solid it is, with a predicted error.
      {"scan_with_specks.obj",
       [=] {
         TriangleMesh scan = merged(blob, translated(scaled(blob, 0.01), {0.5, 0.0, 0.0}));
         const auto lone = static_cast<std::uint32_t>(scan.vertices.size());
         scan.vertices.insert(scan.vertices.end(),
                              {Vec3(0, 0, 0.5), Vec3(0.001, 0, 0.5), Vec3(0, 0.001, 0.5)});
         scan.triangles.push_back({lone, lone + 1, lone + 2});
         return test::objText(scan);
       },
       "",
       [=](const nlohmann::json& q) {
         massNear(core::computeMassProperties(blob)->volume)(q);
         EXPECT_EQ(q["specks_dropped"].get<int>(), 2);
         EXPECT_TRUE(q["physics"]["warnings"].empty()) << q["physics"]["warnings"].dump();
         EXPECT_TRUE(q.contains("predicted_frequency_error"));
       }},
      // A hollow solid: the outer blob and a smaller one wound inward inside it (a cavity).
      {"hollow_blob.obj",
       [=] {
         const TriangleMesh inner = scaled(blob, 0.5);
         return test::objText(merged(blob, reversed(inner, inner.triangles.size())));
       },
       "", warns("encloses 1 cavity")},
      // Text oddities: CRLF line ends, a 4 MB comment line.
      {"crlf.obj",
       [=] {
         std::string text = test::objText(box), out;
         for (char c : text) {
           if (c == '\n') out.push_back('\r');
           out.push_back(c);
         }
         return out;
       },
       "", massNear(0.3 * 0.2 * 0.1)},
      {"long_comment_line.obj", [=] { return "# " + std::string(4 << 20, 'x') + "\n" + test::objText(box); },
       "", massNear(0.3 * 0.2 * 0.1)},
  };
}

// One test over the whole corpus, so that the database is built once per process (ctest runs each test
// in a process of its own): each case is traced by its file name, and every failure names it.
class HostileInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    sDir = std::make_unique<test::ScratchDir>("hostile");
    test::ProcessResult built =
        test::runProcess(SHAPEDB_CLI, {"build", (*sDir / "small.db").string(), "--entries", "8", "--families",
                                       "box,ellipsoid", "--modes", "4", "--quiet"});
    if (built.exitCode != 0) sBuildError = "shapedb build failed: " + built.err;
  }
  static void TearDownTestSuite() { sDir.reset(); }
  void SetUp() override { ASSERT_TRUE(sBuildError.empty()) << sBuildError; }

  static inline std::unique_ptr<test::ScratchDir> sDir;
  static inline std::string sBuildError;
};

void checkCase(const Case& c, const std::filesystem::path& dir) {
  SCOPED_TRACE(c.file);
  const auto file = dir / c.file;
  test::writeFile(file, c.content());
  const test::ProcessResult q =
      test::runProcess(SHAPEDB_CLI, {"query", (dir / "small.db").string(), file.string(), "--json"},
                       {.timeoutSeconds = 120.0});
  // For the log (and docs/reliability.md): what each input gave.
  std::printf("%s: exit %d, %.0f MiB, %s\n", c.file.c_str(), q.exitCode,
              static_cast<double>(q.maxRssKiB) / 1024.0,
              q.exitCode == 0 ? "query succeeded" : q.err.substr(0, q.err.find('\n')).c_str());
  ASSERT_FALSE(q.timedOut) << c.file << " hung";
  ASSERT_LT(q.exitCode, 128) << c.file << " crashed: " << q.err;
  EXPECT_LT(q.maxRssKiB, 2 << 20) << c.file << ": peak memory " << q.maxRssKiB << " KiB";
  if (c.message.empty()) {
    ASSERT_EQ(q.exitCode, 0) << q.err;
    const nlohmann::json j = nlohmann::json::parse(q.out);
    const nlohmann::json& query = j["queries"][0];
    EXPECT_FALSE(query["matches"].empty());
    EXPECT_TRUE(std::isfinite(query["physics"]["mass"].get<double>()));
    EXPECT_GT(query["physics"]["mass"].get<double>(), 0.0);
    if (c.check) c.check(query);
  } else {
    EXPECT_EQ(q.exitCode, 1) << q.err;
    EXPECT_NE(q.err.find(file.string() + ": "), std::string::npos) << "the file is not named: " << q.err;
    EXPECT_NE(q.err.find(c.message), std::string::npos) << "expected '" << c.message << "' in: " << q.err;
  }
}

TEST_F(HostileInput, EachInputGivesItsDocumentedErrorOrResult) {
  const std::vector<Case> cases = corpus();
  ASSERT_GE(cases.size(), 30u);
  for (const Case& c : cases)
    checkCase(c, sDir->path());
}

/// A closed UV ellipsoid of 10,000,000 triangles as binary PLY (186 MB), written directly: the query
/// must read, validate, describe and match it with a correct volume, in bounded memory (it peaked at
/// 2.9 GiB until the closest-point tree of the fidelity report was made lighter; about 1.4 GiB since).
/// Where the memory is not there (an address-space limit of 1 GB, here), the file is refused before it
/// is read, with what it would need.
TEST_F(HostileInput, TenMillionTriangleMeshIsQueriedInBoundedMemory) {
  const int slices = 2500, stacks = 2001;  // 2 · slices · (stacks − 1) = 10,000,000 triangles
  const TriangleMesh mesh = core::makeUvEllipsoid({0.2, 0.1, 0.05}, slices, stacks);
  ASSERT_EQ(mesh.triangles.size(), 10'000'000u);
  const auto file = *sDir / "ten_million.ply";
  {
    std::ofstream out(file, std::ios::binary);
    out << plyHeader("binary_little_endian", mesh.vertices.size(), mesh.triangles.size());
    for (const Vec3& p : mesh.vertices) {
      const float v[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      out.write(reinterpret_cast<const char*>(v), sizeof v);
    }
    for (const auto& t : mesh.triangles) {
      const char three = 3;
      const int f[3] = {static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])};
      out.write(&three, 1);
      out.write(reinterpret_cast<const char*>(f), sizeof f);
    }
    ASSERT_TRUE(out.good());
  }
  const test::ProcessResult limited =
      test::runProcess("/bin/sh", {"-c", "ulimit -v 1000000 && exec \"$0\" \"$@\"", SHAPEDB_CLI, "query",
                                   (*sDir / "small.db").string(), file.string(), "--json"});
  EXPECT_EQ(limited.exitCode, 1) << limited.err;
  EXPECT_NE(limited.err.find(file.string() + ": a mesh of 10000000 faces and "), std::string::npos)
      << limited.err;
  EXPECT_NE(limited.err.find("available: not read"), std::string::npos) << limited.err;
  const test::ProcessResult q =
      test::runProcess(SHAPEDB_CLI, {"query", (*sDir / "small.db").string(), file.string(), "--json"},
                       {.timeoutSeconds = 500.0});
  std::filesystem::remove(file);
  ASSERT_FALSE(q.timedOut);
  ASSERT_EQ(q.exitCode, 0) << q.err;
  const nlohmann::json j = nlohmann::json::parse(q.out);
  const nlohmann::json& query = j["queries"][0];
  EXPECT_EQ(query["triangles"], 10'000'000u);
  const double volume = 4.0 / 3.0 * M_PI * 0.2 * 0.1 * 0.05;  // the tessellation is 1e-6 below this
  EXPECT_NEAR(query["volume"].get<double>(), volume, 1e-5 * volume);
  EXPECT_EQ(query["matches"][0]["family"], "ellipsoid");
  std::printf("10M triangles: peak memory %.0f MiB\n", static_cast<double>(q.maxRssKiB) / 1024.0);
  EXPECT_LT(q.maxRssKiB, 1'677'722) << "peak memory " << q.maxRssKiB << " KiB";  // 1.6 GiB
}

}  // namespace
}  // namespace shapedb::cli
