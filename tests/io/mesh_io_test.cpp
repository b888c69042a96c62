#include <cstring>
#include <fstream>
#include <numbers>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/primitives.h>
#include <shapedb/io/mesh_io.h>

#include "io/load_checks.h"
#include "support/mesh_files.h"
#include "support/test_support.h"

namespace shapedb::io {
namespace {

using core::TriangleMesh;
using core::Vec3;

using test::asciiStl;
using test::binaryStl;
using test::offText;

using test_checks::mustFail;
using test_checks::mustLoad;
using test_checks::volumeOf;

TEST(MeshIo, ObjAndPlyRoundTripExactly) {
  test::ScratchDir dir("io");
  // Coordinates far from the origin, as scans' are, with all 53 bits in use: written and read back to the
  // last bit (a float would move these by centimetres).
  TriangleMesh blob = test::makeLopsidedBlob({1.0, 1.6, 0.7}, 3);
  for (core::Vec3& p : blob.vertices)
    p = p * (1.0 + 1e-9) + core::Vec3(6.4e5, -1.3e6, 0.1);
  for (const char* name : {"blob.obj", "blob.ply", "ascii.ply", "UPPER.OBJ"}) {
    SCOPED_TRACE(name);
    const bool binary = std::string(name) != "ascii.ply";
    ASSERT_TRUE(saveMesh(blob, dir / name, {.binary = binary}).ok());
    const LoadedMesh loaded = mustLoad(dir / name);
    ASSERT_EQ(loaded.mesh.vertices.size(), blob.vertices.size());
    EXPECT_EQ(loaded.mesh.triangles, blob.triangles);
    EXPECT_EQ(loaded.mesh.vertices, blob.vertices);
    EXPECT_TRUE(loaded.topology.isClosed());
    EXPECT_TRUE(loaded.topology.isConsistentlyOriented());
  }
}

TEST(MeshIo, ReadsOffAndBothStlFlavours) {
  test::ScratchDir dir("io");
  const TriangleMesh mesh = core::makeUvEllipsoid({1.0, 0.5, 0.25}, 16, 9);
  test::writeFile(dir / "m.off", offText(mesh));
  test::writeFile(dir / "ascii.stl", asciiStl(mesh));
  test::writeFile(dir / "binary.stl", binaryStl(mesh));
  const double volume = volumeOf(mesh);
  for (const char* name : {"m.off", "ascii.stl", "binary.stl"}) {
    SCOPED_TRACE(name);
    const LoadedMesh loaded = mustLoad(dir / name);
    // STL repeats corners per triangle; the reader merges them back into shared vertices.
    EXPECT_EQ(loaded.mesh.vertices.size(), mesh.vertices.size());
    EXPECT_EQ(loaded.mesh.triangles.size(), mesh.triangles.size());
    EXPECT_TRUE(loaded.topology.isClosed());
    EXPECT_TRUE(loaded.topology.isConsistentlyOriented());
    EXPECT_NEAR(volumeOf(loaded.mesh), volume, 1e-6 * volume);  // STL stores floats
  }
}

TEST(MeshIo, TriangulatesPolygons) {
  test::ScratchDir dir("io");
  test::writeFile(dir / "cube.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                  "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
  const LoadedMesh loaded = mustLoad(dir / "cube.obj");
  EXPECT_EQ(loaded.mesh.triangles.size(), 12u);
  EXPECT_EQ(loaded.polygonsTriangulated, 6u);
  EXPECT_TRUE(loaded.topology.isClosed());
  EXPECT_NEAR(volumeOf(loaded.mesh), 1.0, 1e-15);

  // The same with statements continued on the next line by a backslash, as the format allows, and an
  // error in one named by the line it starts on.
  test::writeFile(dir / "continued.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 \\\r\n1\n"
                  "f 1 3 \\\n4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 \\  \n  8 \\\n6\n");
  const LoadedMesh continued = mustLoad(dir / "continued.obj");
  EXPECT_EQ(continued.mesh.triangles.size(), 12u);
  EXPECT_NEAR(volumeOf(continued.mesh), 1.0, 1e-15);
  test::writeFile(dir / "continued_bad.obj", "v 0 0 0\nv 1 0 \\\n0\nv 0 1 \\\nnan\n");
  const Error bad = mustFail(dir / "continued_bad.obj");
  EXPECT_NE(bad.message.find("line 4: non-finite number 'nan'"), std::string::npos) << bad.message;
}

TEST(MeshIo, KeepsNonManifoldFacesForTheTopologyReport) {
  test::ScratchDir dir("io");
  // A closed tetrahedron with a fin on edge 1-2.
  test::writeFile(
      dir / "fin.obj",
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\nf 1 2 5\n");
  const LoadedMesh loaded = mustLoad(dir / "fin.obj");
  EXPECT_EQ(loaded.mesh.triangles.size(), 5u);
  EXPECT_EQ(loaded.topology.nonManifoldEdges, 1u);
  EXPECT_EQ(loaded.topology.boundaryEdges, 2u);
  // Written back as it is, fin and all: a writer does not repair.
  for (const char* name : {"fin_copy.obj", "fin_copy.ply"}) {
    ASSERT_TRUE(saveMesh(loaded.mesh, dir / name).ok());
    const LoadedMesh again = mustLoad(dir / name);
    EXPECT_EQ(again.mesh.triangles, loaded.mesh.triangles);
    EXPECT_EQ(again.topology.nonManifoldEdges, 1u);
  }
}

TEST(MeshIo, MissingUnreadableOrUnknownFilesAreErrors) {
  test::ScratchDir dir("io");
  EXPECT_EQ(mustFail(dir / "absent.obj").code, ErrorCode::kIo);
  std::filesystem::create_directories(dir / "folder.obj");
  EXPECT_EQ(mustFail(dir / "folder.obj").code, ErrorCode::kIo);
  test::writeFile(dir / "mesh.xyz", "v 0 0 0\n");
  const Error unknown = mustFail(dir / "mesh.xyz");
  EXPECT_EQ(unknown.code, ErrorCode::kUnknownFormat);
  EXPECT_NE(unknown.message.find("unknown mesh format '.xyz'"), std::string::npos);
  test::writeFile(dir / "noextension", "v 0 0 0\n");
  EXPECT_EQ(mustFail(dir / "noextension").code, ErrorCode::kUnknownFormat);
}

TEST(MeshIo, EmptyGarbageAndTruncatedFilesOfEachFormatAreErrors) {
  test::ScratchDir dir("io");
  std::string garbage;
  for (int i = 0; i < 4096; ++i)
    garbage.push_back(static_cast<char>((i * 7919 + 13) % 256));
  const TriangleMesh blob = test::makeLopsidedBlob({1.0, 1.6, 0.7}, 2);
  ASSERT_TRUE(saveMesh(blob, dir / "whole.ply").ok());
  ASSERT_TRUE(saveMesh(blob, dir / "whole_ascii.ply", {.binary = false}).ok());
  ASSERT_TRUE(saveMesh(blob, dir / "whole.obj").ok());
  std::ifstream plyIn(dir / "whole.ply", std::ios::binary);
  const std::string ply((std::istreambuf_iterator<char>(plyIn)), {});
  const std::string stl = binaryStl(blob);

  for (const char* ext : {"obj", "ply", "off", "stl"}) {
    SCOPED_TRACE(ext);
    test::writeFile(dir / (std::string("empty.") + ext), "");
    EXPECT_EQ(mustFail(dir / (std::string("empty.") + ext)).code, ErrorCode::kParse);
    test::writeFile(dir / (std::string("garbage.") + ext), garbage);
    const ErrorCode code = mustFail(dir / (std::string("garbage.") + ext)).code;
    EXPECT_TRUE(code == ErrorCode::kParse || code == ErrorCode::kEmptyMesh ||
                code == ErrorCode::kIndexOutOfRange)
        << static_cast<int>(code);
  }

  // Binary STL cut short, or claiming more triangles than it holds (2³¹ among them).
  test::writeFile(dir / "truncated.stl", stl.substr(0, stl.size() - 30));
  const Error truncated = mustFail(dir / "truncated.stl");
  EXPECT_EQ(truncated.code, ErrorCode::kParse);
  EXPECT_NE(truncated.message.find("truncated or corrupt binary STL"), std::string::npos)
      << truncated.message;
  // The same with a header that starts as ASCII STL does, as SolidWorks writes it.
  std::string solidHeader = stl.substr(0, stl.size() - 30);
  solidHeader.replace(0, 11, "solid blob ");
  test::writeFile(dir / "truncated_solid.stl", solidHeader);
  const Error truncatedSolid = mustFail(dir / "truncated_solid.stl");
  EXPECT_NE(truncatedSolid.message.find("truncated or corrupt binary STL"), std::string::npos)
      << truncatedSolid.message;
  test::writeFile(dir / "liar.stl", binaryStl(blob, 1u << 31));
  EXPECT_EQ(mustFail(dir / "liar.stl").code, ErrorCode::kParse);
  test::writeFile(dir / "short.stl", stl.substr(0, 40));
  EXPECT_EQ(mustFail(dir / "short.stl").code, ErrorCode::kParse);

  // Binary PLY cut in its face list, and cut in its vertex list.
  test::writeFile(dir / "truncated_faces.ply", ply.substr(0, ply.size() - 100));
  mustFail(dir / "truncated_faces.ply");
  test::writeFile(dir / "truncated_vertices.ply", ply.substr(0, ply.find("end_header") + 200));
  mustFail(dir / "truncated_vertices.ply");
}

TEST(MeshIo, InvalidContentIsReportedWithItsCode) {
  test::ScratchDir dir("io");
  const std::string tet = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  const std::string faces = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  struct Case {
    const char* name;
    std::string content;
    ErrorCode code;
  };
  const Case cases[] = {
      {"nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + faces, ErrorCode::kNonFinite},
      {"inf.obj", "v 0 0 inf\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + faces, ErrorCode::kNonFinite},
      {"overflow.obj", "v 0 0 1e400\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + faces, ErrorCode::kNonFinite},
      {"vertices_only.obj", tet, ErrorCode::kEmptyMesh},
      {"out_of_range.obj", tet + faces + "f 1 2 9\n", ErrorCode::kIndexOutOfRange},
      {"negative_out_of_range.obj", tet + faces + "f -1 -2 -9\n", ErrorCode::kIndexOutOfRange},
      {"nan.off", "OFF\n4 4 0\n0 0 0\n1 0 nan\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n",
       ErrorCode::kNonFinite},
      {"inf.ply",
       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
       "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 -inf\n0 1 0\n0 0 1\n"
       "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n",
       ErrorCode::kNonFinite},
      {"unparsable_vertex.obj", "v 0 0 zero\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + faces, ErrorCode::kParse},
      {"two_coordinates.obj", "v 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + faces, ErrorCode::kParse},
      {"corner_without_vertex.obj", tet + faces + "f /1 2/1 3/1\n", ErrorCode::kParse},
      {"zero_index.obj", tet + faces + "f 0 1 2\n", ErrorCode::kIndexOutOfRange},
      {"index_beyond_int.obj", tet + faces + "f 1 2 99999999999999999999\n", ErrorCode::kIndexOutOfRange},
      {"repeated.off",
       "OFF\n4 5 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n3 0 0 1\n",
       ErrorCode::kDegenerateFace},
      {"collinear.obj", tet + "v 0.5 0 0\n" + faces + "f 1 5 2\n", ErrorCode::kDegenerateFace},
      {"out_of_range.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 7\n", ErrorCode::kIndexOutOfRange},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    test::writeFile(dir / c.name, c.content);
    const Error error = mustFail(dir / c.name);
    EXPECT_EQ(error.code, c.code) << error.message;
  }
}

TEST(MeshIo, ObjRepeatedCornersAreMergedAndAFaceLeftWithTwoIsDegenerate) {
  test::ScratchDir dir("io");
  // "f 1 1 2" is an edge once its repeated corner is merged: degenerate, dropped only when asked.
  test::writeFile(dir / "tet.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\nf 1 1 2\n");
  EXPECT_EQ(mustFail(dir / "tet.obj").code, ErrorCode::kDegenerateFace);
  const LoadedMesh loaded = mustLoad(dir / "tet.obj", {.allowDegenerateFaces = true});
  EXPECT_EQ(loaded.mesh.triangles.size(), 4u);
  EXPECT_EQ(loaded.facesDropped, 1u);
  EXPECT_TRUE(loaded.topology.isClosed());
  // A quad with a corner repeated (as some exporters write) is the triangle it is.
  test::writeFile(dir / "quad.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 3 2\nf 1 2 4 1\nf 2 3 4\nf 1 4 3\n");
  const LoadedMesh quad = mustLoad(dir / "quad.obj");
  EXPECT_EQ(quad.mesh.triangles.size(), 4u);
  EXPECT_EQ(quad.polygonsTriangulated, 0u);
}

TEST(MeshIo, ObjReaderReadsOnlyGeometryAndNeverAnotherFile) {
  test::ScratchDir dir("io");
  // Texture and normal indices, relative indices, groups, materials (mtllib naming a file that would
  // never end), tabs and CRLF: the geometry alone is read, in double precision.
  test::writeFile(dir / "cube.obj",
                  "mtllib /dev/zero\r\nusemtl steel\r\no cube\r\n"
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1.000000000000001\n"
                  "vt 0 0\nvn 0 0 1\ng sides\ns off\n"
                  "f 1/1 3/1 4/1 2/1\nf 5//1 6//1 8//1 7//1\nf\t1/1/1\t2/1/1\t6/1/1\t5/1/1\r\n"
                  "f -6 -2 -1 -5\nf 1 5 7 3\nf 2 4 8 6\nl 1 2\n");
  const LoadedMesh loaded = mustLoad(dir / "cube.obj");
  EXPECT_EQ(loaded.mesh.triangles.size(), 12u);
  EXPECT_TRUE(loaded.topology.isClosed());
  EXPECT_EQ(loaded.mesh.vertices[7].z(), 1.000000000000001);
}

TEST(MeshIo, DegenerateFacesAreAcceptedOnlyWhenAsked) {
  test::ScratchDir dir("io");
  test::writeFile(dir / "tet.off",
                  "OFF\n4 5 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n3 0 0 1\n");
  EXPECT_EQ(mustFail(dir / "tet.off").code, ErrorCode::kDegenerateFace);
  const LoadedMesh loaded = mustLoad(dir / "tet.off", {.allowDegenerateFaces = true});
  EXPECT_EQ(loaded.facesDropped, 1u);
  EXPECT_EQ(loaded.defects.repeatedVertexFaces, 1u);
  EXPECT_EQ(loaded.mesh.triangles.size(), 4u);
  EXPECT_TRUE(loaded.topology.isClosed());
}

// A closed surface with a T-junction (a vertex on an edge of the unit cube's bottom face, on the front
// side only, closed by a zero-area face) is read, the face flipped away, and said so; a zero-area face
// that leaves the surface open (a fin on a tet) is refused as before; asked to keep degenerate faces, the
// loader keeps it.
TEST(MeshIo, AZeroAreaFaceOfATJunctionIsFlippedAwayAtLoad) {
  test::ScratchDir dir("io-tjunction");
  const std::string cube =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 0.5 0 0\n"
      "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 9 6\nf 1 6 5\nf 9 2 6\nf 1 2 9\nf 2 3 7\nf 2 7 6\n"
      "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
  test::writeFile(dir / "cube.obj", cube);
  const LoadedMesh loaded = mustLoad(dir / "cube.obj");
  EXPECT_EQ(loaded.zeroAreaFacesFlipped, 1u);
  EXPECT_EQ(loaded.defects.zeroAreaFaces, 1u);  // as read
  EXPECT_EQ(core::findDefects(loaded.mesh).zeroAreaFaces, 0u);
  EXPECT_TRUE(loaded.topology.isClosed() && loaded.topology.isConsistentlyOriented());
  EXPECT_NEAR(volumeOf(loaded.mesh), 1.0, 1e-15);
  ASSERT_EQ(loaded.notes().size(), 1u);
  EXPECT_NE(loaded.notes().front().find("1 zero-area face"), std::string::npos) << loaded.notes().front();
  const LoadedMesh kept = mustLoad(dir / "cube.obj", {.allowDegenerateFaces = true});
  EXPECT_EQ(kept.zeroAreaFacesFlipped, 0u);
  EXPECT_EQ(core::findDefects(kept.mesh).zeroAreaFaces, 1u);

  // Two vertices on the one edge (a fan of two fillers): flipped away in turn.
  test::writeFile(dir / "fan.obj",
                  "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 0.3 0 0\n"
                  "v 0.6 0 0\nf 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 9 5\nf 9 6 5\nf 9 10 6\nf 10 2 6\n"
                  "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\nf 1 2 10\nf 1 10 9\n");
  const LoadedMesh fan = mustLoad(dir / "fan.obj");
  EXPECT_EQ(fan.zeroAreaFacesFlipped, 2u);
  EXPECT_EQ(core::findDefects(fan.mesh).zeroAreaFaces, 0u);
  EXPECT_TRUE(fan.topology.isClosed() && fan.topology.isConsistentlyOriented());
  EXPECT_NEAR(volumeOf(fan.mesh), 1.0, 1e-15);

  test::writeFile(dir / "fin.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0.5 0 0\n"
                  "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\nf 1 5 2\n");
  EXPECT_EQ(mustFail(dir / "fin.obj").code, ErrorCode::kDegenerateFace);
}

// Shells of one surface, each oriented by what is around it: a shell wound inward inside a solid is a
// cavity and stays; one wound inward apart from every solid, or loose in a cavity, is a solid inside
// out, and is turned outward with a note; the volumes are then the solids' less their cavities.
TEST(MeshIo, AShellWoundInwardIsACavityOnlyInsideASolid) {
  test::ScratchDir dir("io-shells");
  const TriangleMesh ball = core::makeIcosphere(1.0, 2);
  const double v = volumeOf(ball);
  struct Case {
    std::string name;
    TriangleMesh mesh;
    std::size_t turned;
    double volume;
  };
  const TriangleMesh hollow = test::withShell(ball, ball, Vec3::Zero(), true, 0.5);
  const std::vector<Case> cases = {
      {"hollow", hollow, 0, v * (1.0 - 0.125)},
      {"apart", test::withShell(ball, ball, Vec3(3, 0, 0), true, 0.5), 1, v * 1.125},
      {"loose", test::withShell(hollow, ball, Vec3::Zero(), true, 0.25), 1, v * (1.0 - 0.125 + 0.015625)},
      {"loose_outward", test::withShell(hollow, ball, Vec3::Zero(), false, 0.25), 0,
       v * (1.0 - 0.125 + 0.015625)},
  };
  for (const Case& c : cases) {
    const auto path = dir / (c.name + ".obj");
    ASSERT_TRUE(saveMesh(c.mesh, path).ok());
    const LoadedMesh loaded = mustLoad(path);
    EXPECT_EQ(loaded.shellsTurnedOutward, c.turned) << c.name;
    EXPECT_NEAR(volumeOf(loaded.mesh), c.volume, 1e-12 * v) << c.name;
    EXPECT_EQ(loaded.notes().empty(), c.turned == 0) << c.name;
    const LoadedMesh asRead = mustLoad(path, {.orientOutward = false});
    EXPECT_EQ(asRead.shellsTurnedOutward, 0u) << c.name;
  }
}

TEST(MeshIo, DetachedSpecksAreDroppedAndSaidSo) {
  test::ScratchDir dir("io-specks");
  const TriangleMesh ball = core::makeIcosphere(1.0, 3);  // area 4π
  // Beside the ball, as a scan leaves them: two closed specks (tiny balls, area shares 1.6e-5 and 1e-4)
  // and an open one (a lone triangle).
  TriangleMesh scan = test::withShell(ball, ball, Vec3(3, 0, 0), false, 0.004);
  scan = test::withShell(scan, ball, Vec3(0, 3, 0), false, 0.01);
  const auto lone = static_cast<std::uint32_t>(scan.vertices.size());
  scan.vertices.insert(scan.vertices.end(), {Vec3(0, 0, 3), Vec3(0.01, 0, 3), Vec3(0, 0.01, 3)});
  scan.triangles.push_back({lone, lone + 1, lone + 2});
  ASSERT_TRUE(saveMesh(scan, dir / "scan.obj").ok());

  const LoadedMesh loaded = mustLoad(dir / "scan.obj");
  EXPECT_EQ(loaded.specksDropped, 3u);
  EXPECT_EQ(loaded.mesh.vertices, ball.vertices);  // the ball's, in their order
  EXPECT_EQ(loaded.mesh.triangles, ball.triangles);
  EXPECT_TRUE(loaded.topology.isClosed());
  const double ballArea = 4.0 * std::numbers::pi * 1.0;
  EXPECT_NEAR(loaded.specksAreaShare,
              (0.004 * 0.004 + 0.01 * 0.01 + 0.5e-4 / ballArea) /
                  (1.0 + 0.004 * 0.004 + 0.01 * 0.01 + 0.5e-4 / ballArea),
              0.02 * loaded.specksAreaShare);
  EXPECT_NEAR(loaded.specksVolumeShare,
              (std::pow(0.004, 3) + std::pow(0.01, 3)) / (1.0 + std::pow(0.004, 3) + std::pow(0.01, 3)),
              1e-9);
  ASSERT_EQ(loaded.notes().size(), 1u);
  EXPECT_NE(loaded.notes()[0].find("3 detached parts under 0.001 of the largest part's area dropped"),
            std::string::npos)
      << loaded.notes()[0];

  // Kept when asked: the lone triangle leaves the surface open.
  const LoadedMesh kept = mustLoad(dir / "scan.obj", {.dropSpecks = false});
  EXPECT_EQ(kept.specksDropped, 0u);
  EXPECT_EQ(kept.mesh.triangles.size(), scan.triangles.size());
  EXPECT_FALSE(kept.topology.isClosed());

  // A part over the share is no speck: two solids, both kept.
  const TriangleMesh pair = test::withShell(ball, ball, Vec3(3, 0, 0), false, 0.04);  // share 1.6e-3
  ASSERT_TRUE(saveMesh(pair, dir / "pair.obj").ok());
  const LoadedMesh both = mustLoad(dir / "pair.obj");
  EXPECT_EQ(both.specksDropped, 0u);
  EXPECT_EQ(both.topology.components, 2u);
}

TEST(MeshIo, ASurfaceWoundInwardIsFlippedAtLoadAndSaysSo) {
  test::ScratchDir dir("mesh-io-flip");
  const TriangleMesh box = core::makeBox({0.3, 0.2, 0.1});
  TriangleMesh inward = box;
  for (auto& t : inward.triangles)
    std::swap(t[1], t[2]);
  // Far from the origin, as scans are: the sign must not drown in the coordinates' digits.
  for (Vec3& p : inward.vertices)
    p += Vec3(4.0e5, -3.0e5, 2.0e5);
  test::writeFile(dir / "inward.obj", test::objText(inward));

  const LoadedMesh loaded = mustLoad(dir / "inward.obj");
  EXPECT_TRUE(loaded.flippedInsideOut);
  EXPECT_NEAR(loaded.signedVolumeAsRead, -0.006, 1e-9);
  EXPECT_NEAR(volumeOf(loaded.mesh), 0.006, 1e-9);
  ASSERT_EQ(loaded.notes().size(), 1u);
  EXPECT_NE(loaded.notes().front().find("wound inward"), std::string::npos);

  const LoadedMesh asIs = mustLoad(dir / "inward.obj", {.orientOutward = false});
  EXPECT_FALSE(asIs.flippedInsideOut);
  EXPECT_EQ(asIs.mesh.triangles, inward.triangles);

  // Outward already: untouched, nothing to say. One face reversed: no flip can fix it, so none is made.
  test::writeFile(dir / "outward.obj", test::objText(box));
  EXPECT_FALSE(mustLoad(dir / "outward.obj").flippedInsideOut);
  EXPECT_TRUE(mustLoad(dir / "outward.obj").notes().empty());
  TriangleMesh oneFace = box;
  std::swap(oneFace.triangles[0][1], oneFace.triangles[0][2]);
  test::writeFile(dir / "one_face.obj", test::objText(oneFace));
  const LoadedMesh inconsistent = mustLoad(dir / "one_face.obj");
  EXPECT_FALSE(inconsistent.flippedInsideOut);
  EXPECT_EQ(inconsistent.mesh.triangles, oneFace.triangles);
}

TEST(MeshIo, AnOpenSoupIsWeldedClosedAndAClosedSurfaceIsLeftAlone) {
  test::ScratchDir dir("mesh-io-weld");
  const TriangleMesh box = core::makeBox({0.3, 0.2, 0.1});
  // As binary STL writers store surfaces: three corners per triangle, nothing shared. (OpenMesh's STL
  // reader merges exactly equal corners itself, so the soup goes through OBJ.)
  const TriangleMesh soup = test::soupOf(box);
  test::writeFile(dir / "soup.obj", test::objText(soup));
  const LoadedMesh welded = mustLoad(dir / "soup.obj");
  EXPECT_TRUE(welded.topology.isClosed());
  EXPECT_EQ(welded.verticesWelded, soup.vertices.size() - box.vertices.size());
  EXPECT_NEAR(volumeOf(welded.mesh), 0.006, 1e-12);
  ASSERT_EQ(welded.notes().size(), 1u);
  EXPECT_NE(welded.notes().front().find("welded"), std::string::npos);
  EXPECT_FALSE(mustLoad(dir / "soup.obj", {.weld = false}).topology.isClosed());

  // Two closed boxes that share an edge's positions (an assembly exported as one file): each is closed
  // as read, so nothing is welded into a non-manifold edge.
  TriangleMesh pair = box;
  TriangleMesh moved = box;
  for (Vec3& p : moved.vertices)
    p += Vec3(0.3, 0.2, 0.0);
  core::append(pair, moved);
  test::writeFile(dir / "pair.obj", test::objText(pair));
  const LoadedMesh asIs = mustLoad(dir / "pair.obj");
  EXPECT_EQ(asIs.verticesWelded, 0u);
  EXPECT_EQ(asIs.mesh.vertices.size(), pair.vertices.size());
  EXPECT_TRUE(asIs.topology.isClosed());
}

TEST(MeshIo, UnitsScaleTheCoordinatesAsTheyAreRead) {
  test::ScratchDir dir("mesh-io-units");
  test::writeFile(dir / "tray_mm.obj", test::objText(core::makeBox({300.0, 200.0, 10.0})));
  EXPECT_EQ(unitScale("mm"), 0.001);
  EXPECT_EQ(unitScale("in"), 0.0254);
  EXPECT_EQ(unitScale("ft"), 0.3048);
  EXPECT_FALSE(unitScale("furlong").has_value());
  const LoadedMesh metres = mustLoad(dir / "tray_mm.obj", {.scale = *unitScale("mm")});
  EXPECT_EQ(metres.scale, 0.001);
  EXPECT_NEAR(volumeOf(metres.mesh), 0.3 * 0.2 * 0.01, 1e-12);
  EXPECT_EQ(mustFail(dir / "tray_mm.obj", {.scale = 0.0}).code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(mustFail(dir / "tray_mm.obj", {.scale = -1.0}).code, ErrorCode::kInvalidArgument);
}

// A file's mesh size comes from its header (PLY, OFF, binary STL) or its lines, counted in one pass (OBJ
// and ASCII STL over 16 MiB), and a file whose mesh would not fit in the memory there is is refused before
// it is read, with the figures.
TEST(MeshIo, AFileTooLargeForTheMemoryIsRefusedBeforeItIsRead) {
  test::ScratchDir dir("mesh-io-size");
  const TriangleMesh sphere = core::makeUvEllipsoid({0.1, 0.1, 0.1}, 800, 400);
  ASSERT_TRUE(saveMesh(sphere, dir / "sphere.ply").ok());
  test::writeFile(dir / "sphere.obj", test::objText(sphere));
  test::writeFile(dir / "sphere.stl", test::binaryStl(sphere));
  ASSERT_GT(std::filesystem::file_size(dir / "sphere.obj"), 16u << 20);  // so that its lines are counted
  for (const char* name : {"sphere.ply", "sphere.obj"}) {
    SCOPED_TRACE(name);
    const Result<MeshFileSize> size = estimateMeshFile(dir / name);
    ASSERT_TRUE(size.ok()) << size.error().message;
    EXPECT_EQ(size->triangles, sphere.triangles.size());
    EXPECT_EQ(size->vertices, sphere.vertices.size());
    const Error refused = mustFail(dir / name, {.memoryBudget = size->bytes() - 1});
    EXPECT_EQ(refused.code, ErrorCode::kTooLarge);
    EXPECT_NE(refused.message.find(std::to_string(sphere.triangles.size()) + " faces"), std::string::npos)
        << refused.message;
    EXPECT_NE(refused.message.find("available"), std::string::npos) << refused.message;
    EXPECT_EQ(mustLoad(dir / name, {.memoryBudget = size->bytes()}).mesh.triangles.size(),
              sphere.triangles.size());
  }
  EXPECT_EQ(mustLoad(dir / "sphere.ply", {.memoryBudget = 0}).mesh.triangles.size(),  // 0: no check
            sphere.triangles.size());
  // Binary STL: its header's count; the corners merged, about half as many vertices as triangles.
  const Result<MeshFileSize> stl = estimateMeshFile(dir / "sphere.stl");
  ASSERT_TRUE(stl.ok()) << stl.error().message;
  EXPECT_EQ(stl->triangles, sphere.triangles.size());
  EXPECT_EQ(mustFail(dir / "sphere.stl", {.memoryBudget = 1u << 20}).code, ErrorCode::kTooLarge);

  // A header whose count the file cannot hold is a corrupt file, not a huge mesh: the reader says so.
  std::string corrupt =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\nend_header\n";
  corrupt.resize(2u << 20, '\0');
  test::writeFile(dir / "corrupt.ply", corrupt);
  const Result<MeshFileSize> capped = estimateMeshFile(dir / "corrupt.ply");
  ASSERT_TRUE(capped.ok());
  EXPECT_LE(capped->triangles, (2u << 20) / 4);
  EXPECT_NE(mustFail(dir / "corrupt.ply", {.memoryBudget = 1u << 30}).code, ErrorCode::kTooLarge);
  // Nor is a file of 2 MiB without a line end read whole to find its header: nothing counted.
  test::writeFile(dir / "one_line.ply", "ply" + std::string(2u << 20, 'x'));
  const Result<MeshFileSize> none = estimateMeshFile(dir / "one_line.ply");
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->triangles, 0u);
  EXPECT_EQ(mustFail(dir / "one_line.ply").code, ErrorCode::kParse);
}

// The memory available is the least of the system's, the control group's and the address-space limit's:
// under `ulimit -v` (here set in a child process), little more than what the limit leaves.
TEST(MeshIo, AvailableMemoryHonoursTheAddressSpaceLimit) {
  const std::optional<std::uint64_t> system = availableMemory();
  ASSERT_TRUE(system.has_value()) << "/proc/meminfo unreadable";
  EXPECT_GT(*system, 0u);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::ifstream statm("/proc/self/statm");
    std::uint64_t pages = 0;
    statm >> pages;
    const std::uint64_t mapped = pages * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
    const rlimit limit{mapped + (64u << 20), mapped + (64u << 20)};
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(2);
    const std::optional<std::uint64_t> left = availableMemory();
    _exit(left && *left <= (64u << 20) ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST(MeshIo, SaveRejectsUnknownFormatsAndInvalidMeshes) {
  test::ScratchDir dir("io");
  const TriangleMesh box = core::makeBox({1, 1, 1});
  EXPECT_EQ(saveMesh(box, dir / "box.stl").error().code, ErrorCode::kUnknownFormat);
  TriangleMesh bad = box;
  bad.triangles[0][0] = 99;
  EXPECT_EQ(saveMesh(bad, dir / "bad.obj").error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(saveMesh(box, dir / "missing_folder" / "box.obj").error().code, ErrorCode::kIo);
}

}  // namespace
}  // namespace shapedb::io
