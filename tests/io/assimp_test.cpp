// FBX and COLLADA files, read through assimp in a worker process (io/src/assimp_reader.h): files written
// here by hand, as the formats define them, and read back through loadMesh.
#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include <shapedb/core/topology.h>
#include <shapedb/io/mesh_io.h>

#include "io/load_checks.h"
#include "support/test_support.h"

namespace shapedb::io::assimp_test {
namespace {

using test_checks::mustFail;
using test_checks::mustLoad;
using test_checks::volumeOf;

/// A COLLADA scene of one unit cube (outward-wound triangles) placed by two nodes: stretched by (2, 3, 4)
/// and moved by (10, 0, 0), and mirrored in x and moved by (−10, 0, 0), in units of `meter` metres, Y up
/// (assimp turns other up axes to Y).
std::string colladaCubes(double meter) {
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="unit" meter=")" +
         std::to_string(meter) + R"("/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="cube" name="cube">
      <mesh>
        <source id="cube-positions">
          <float_array id="cube-array" count="24">0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1</float_array>
          <technique_common><accessor source="#cube-array" count="8" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
          </accessor></technique_common>
        </source>
        <vertices id="cube-vertices"><input semantic="POSITION" source="#cube-positions"/></vertices>
        <triangles count="12">
          <input semantic="VERTEX" source="#cube-vertices" offset="0"/>
          <p>0 2 1 0 3 2 4 5 6 4 6 7 0 1 5 0 5 4 1 2 6 1 6 5 2 3 7 2 7 6 3 0 4 3 4 7</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene" name="scene">
      <node id="stretched" name="stretched">
        <translate>10 0 0</translate><scale>2 3 4</scale><instance_geometry url="#cube"/>
      </node>
      <node id="mirrored" name="mirrored">
        <translate>-10 0 0</translate><scale>-1 1 1</scale><instance_geometry url="#cube"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
}

/// The same two cubes as an ASCII FBX file (quads: the last index of a polygon is written as −i − 1), in
/// units of `unitScaleFactor` centimetres.
std::string fbxCubes(double unitScaleFactor) {
  return R"(; FBX 7.4.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7400
}
GlobalSettings:  {
	Version: 1000
	Properties70:  {
		P: "UnitScaleFactor", "double", "Number", "",)" +
         std::to_string(unitScaleFactor) + R"(
	}
}
Objects:  {
	Geometry: 100, "Geometry::cube", "Mesh" {
		Vertices: *24 {
			a: 0,0,0,1,0,0,1,1,0,0,1,0,0,0,1,1,0,1,1,1,1,0,1,1
		}
		PolygonVertexIndex: *24 {
			a: 0,3,2,-2,4,5,6,-8,0,1,5,-5,1,2,6,-6,2,3,7,-7,3,0,4,-8
		}
	}
	Model: 200, "Model::stretched", "Mesh" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",10,0,0
			P: "Lcl Scaling", "Lcl Scaling", "", "A",2,3,4
		}
	}
	Model: 300, "Model::mirrored", "Mesh" {
		Version: 232
		Properties70:  {
			P: "Lcl Translation", "Lcl Translation", "", "A",-10,0,0
			P: "Lcl Scaling", "Lcl Scaling", "", "A",-1,1,1
		}
	}
}
Connections:  {
	C: "OO",200,0
	C: "OO",100,200
	C: "OO",300,0
	C: "OO",100,300
}
)";
}

/// A binary FBX file (version 7400) of the same two cubes as fbxCubes, written record by record as the
/// format lays them out: each node its end offset, property count and bytes, name, properties (typed:
/// I int32, L int64, D double, S string, d and i uncompressed arrays) and children, closed by a 13-byte
/// null record.
class BinaryFbx {
 public:
  struct Node {
    std::string name;
    std::string properties;  ///< encoded
    std::size_t count = 0;   ///< properties
    std::vector<Node> children;
  };
  static void add(Node& n, std::int32_t v) { n.properties += 'I' + raw(v), ++n.count; }
  static void add(Node& n, std::int64_t v) { n.properties += 'L' + raw(v), ++n.count; }
  static void add(Node& n, double v) { n.properties += 'D' + raw(v), ++n.count; }
  static void add(Node& n, const std::string& v) {
    n.properties += 'S' + raw(static_cast<std::uint32_t>(v.size())) + v, ++n.count;
  }
  template <typename T>
  static void add(Node& n, const std::vector<T>& v) {
    std::string bytes;
    for (const T& x : v)
      bytes += raw(x);
    n.properties += (std::is_same_v<T, double> ? 'd' : 'i') + raw(static_cast<std::uint32_t>(v.size())) +
                    raw(std::uint32_t{0}) + raw(static_cast<std::uint32_t>(bytes.size())) + bytes;
    ++n.count;
  }
  static std::string file(const std::vector<Node>& top) {
    std::string out = std::string("Kaydara FBX Binary  \0\x1a\0", 23) + raw(std::uint32_t{7400});
    for (const Node& n : top)
      out += record(n, out.size());
    return out + std::string(13, '\0');
  }

 private:
  template <typename T>
  static std::string raw(T v) {
    return std::string(reinterpret_cast<const char*>(&v), sizeof v);
  }
  static std::string record(const Node& n, std::size_t offset) {
    std::string children;
    const std::size_t head = 13 + n.name.size() + n.properties.size();
    for (const Node& c : n.children)
      children += record(c, offset + head + children.size());
    if (!n.children.empty()) children += std::string(13, '\0');
    return raw(static_cast<std::uint32_t>(offset + head + children.size())) +
           raw(static_cast<std::uint32_t>(n.count)) + raw(static_cast<std::uint32_t>(n.properties.size())) +
           static_cast<char>(n.name.size()) + n.name + n.properties + children;
  }
};

std::string binaryFbxCubes(double unitScaleFactor) {
  using N = BinaryFbx::Node;
  const auto leaf = [](const std::string& name, auto... values) {
    N n{name, "", 0, {}};
    (BinaryFbx::add(n, values), ...);
    return n;
  };
  const auto placed = [&](std::int64_t id, const std::string& name, double tx,
                          const std::array<double, 3>& s) {
    N model = leaf("Model", id, std::string("Model::") + name, std::string("Mesh"));
    N properties{"Properties70", "", 0, {}};
    properties.children.push_back(leaf("P", std::string("Lcl Translation"), std::string("Lcl Translation"),
                                       std::string(""), std::string("A"), tx, 0.0, 0.0));
    properties.children.push_back(leaf("P", std::string("Lcl Scaling"), std::string("Lcl Scaling"),
                                       std::string(""), std::string("A"), s[0], s[1], s[2]));
    model.children = {leaf("Version", std::int32_t{232}), properties};
    return model;
  };
  N header{"FBXHeaderExtension",
           "",
           0,
           {leaf("FBXHeaderVersion", std::int32_t{1003}), leaf("FBXVersion", std::int32_t{7400})}};
  N units{"Properties70",
          "",
          0,
          {leaf("P", std::string("UnitScaleFactor"), std::string("double"), std::string("Number"),
                std::string(""), unitScaleFactor)}};
  N settings{"GlobalSettings", "", 0, {leaf("Version", std::int32_t{1000}), units}};
  N geometry = leaf("Geometry", std::int64_t{100}, std::string("Geometry::cube"), std::string("Mesh"));
  geometry.children = {
      leaf("Vertices",
           std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1}),
      leaf("PolygonVertexIndex", std::vector<std::int32_t>{0, 3, 2, -2, 4, 5, 6, -8, 0, 1, 5, -5,
                                                           1, 2, 6, -6, 2, 3, 7, -7, 3, 0, 4, -8})};
  N objects{
      "Objects",
      "",
      0,
      {geometry, placed(200, "stretched", 10.0, {2, 3, 4}), placed(300, "mirrored", -10.0, {-1, 1, 1})}};
  const auto link = [&](std::int64_t child, std::int64_t parent) {
    return leaf("C", std::string("OO"), child, parent);
  };
  N connections{"Connections", "", 0, {link(200, 0), link(100, 200), link(300, 0), link(100, 300)}};
  return BinaryFbx::file({header, settings, objects, connections});
}

/// Checks what both files hold, in units of `unit` metres: two closed solids facing out (the mirrored
/// cube rewound), 2·3·4 + 1 cubic units, the stretched one's corners where its node put them.
void expectTwoCubes(const LoadedMesh& loaded, double unit) {
  EXPECT_EQ(loaded.meshInstances, 2u);
  EXPECT_EQ(loaded.mesh.triangleCount(), 24u);
  EXPECT_TRUE(loaded.topology.isClosed());
  EXPECT_TRUE(loaded.topology.isConsistentlyOriented());
  EXPECT_FALSE(loaded.flippedInsideOut);
  EXPECT_EQ(loaded.shellsTurnedOutward, 0u) << "the mirrored cube was read inside out";
  EXPECT_NEAR(volumeOf(loaded.mesh), 25.0 * unit * unit * unit, 1e-6 * 25.0 * unit * unit * unit);
  core::Vec3 lo = core::Vec3::Constant(1e30), hi = core::Vec3::Constant(-1e30);
  for (const core::Vec3& p : loaded.mesh.vertices)
    if (p.x() > 0.0) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  EXPECT_LT((lo - core::Vec3(10, 0, 0) * unit).norm(), 1e-6 * unit);
  EXPECT_LT((hi - core::Vec3(12, 3, 4) * unit).norm(), 1e-6 * unit);
}

TEST(Assimp, ColladaNodesPlaceTheirMeshesInTheFilesUnit) {
  const test::ScratchDir dir("assimp");
  const auto path = dir / "cubes.DAE";  // the extension in any case
  test::writeFile(path, colladaCubes(0.01));
  const LoadedMesh loaded = mustLoad(path);
  EXPECT_EQ(loaded.format, "dae");
  EXPECT_EQ(loaded.fileUnit, 1.0);  // assimp applied COLLADA's unit in the scene itself
  expectTwoCubes(loaded, 0.01);
}

TEST(Assimp, FbxNodesPlaceTheirMeshesAndItsUnitIsApplied) {
  const test::ScratchDir dir("assimp");
  const auto inches = dir / "cubes.fbx";
  test::writeFile(inches, fbxCubes(2.54));
  const LoadedMesh loaded = mustLoad(inches);
  EXPECT_EQ(loaded.format, "fbx");
  EXPECT_NEAR(loaded.fileUnit, 0.0254, 1e-9);  // assimp keeps the factor in single precision
  expectTwoCubes(loaded, 0.0254);
  bool said = false;
  for (const std::string& note : loaded.notes())
    said = said || note.find("unit is 0.0254 m") != std::string::npos;
  EXPECT_TRUE(said) << "the unit goes unsaid";
  // The binary form, as modelling tools write it.
  const auto binary = dir / "binary.fbx";
  test::writeFile(binary, binaryFbxCubes(2.54));
  const LoadedMesh fromBinary = mustLoad(binary);
  EXPECT_NEAR(fromBinary.fileUnit, 0.0254, 1e-9);
  expectTwoCubes(fromBinary, 0.0254);
  // FBX's default unit, the centimetre, and a scale of the caller's on top of it.
  const auto centimetres = dir / "cm.fbx";
  test::writeFile(centimetres, fbxCubes(1.0));
  expectTwoCubes(mustLoad(centimetres), 0.01);
  LoadOptions doubled;
  doubled.scale = 2.0;
  expectTwoCubes(mustLoad(centimetres, doubled), 0.02);
}

TEST(Assimp, MalformedFilesAreErrorsThatNameThem) {
  const test::ScratchDir dir("assimp");
  const auto garbage = dir / "garbage.fbx";
  test::writeFile(garbage, std::string("Kaydara FBX Binary  \0\x1a\0", 23) + std::string(200, '\x7f'));
  EXPECT_EQ(mustFail(garbage).code, ErrorCode::kParse);
  const auto text = dir / "notes.dae";
  test::writeFile(text, "these are not the triangles you are looking for\n");
  EXPECT_EQ(mustFail(text).code, ErrorCode::kParse);
  // Cut in half: the XML ends in the middle of the geometry.
  const std::string whole = colladaCubes(1.0);
  const auto cut = dir / "cut.dae";
  test::writeFile(cut, whole.substr(0, whole.size() / 2));
  EXPECT_EQ(mustFail(cut).code, ErrorCode::kParse);
  // A binary FBX cut short: its records' end offsets point past the end.
  const std::string fbx = binaryFbxCubes(1.0);
  const auto cutFbx = dir / "cut.fbx";
  test::writeFile(cutFbx, fbx.substr(0, fbx.size() / 2));
  EXPECT_EQ(mustFail(cutFbx).code, ErrorCode::kParse);
  // A scene without geometry.
  std::string none = whole;
  const std::size_t from = none.find("<library_geometries>");
  const std::string closing = "</library_geometries>";
  none.erase(from, none.find(closing) + closing.size() - from);
  for (std::size_t at; (at = none.find("<instance_geometry url=\"#cube\"/>")) != std::string::npos;)
    none.erase(at, std::string("<instance_geometry url=\"#cube\"/>").size());
  const auto empty = dir / "empty.dae";
  test::writeFile(empty, none);
  const Error e = mustFail(empty);
  EXPECT_EQ(e.code, ErrorCode::kEmptyMesh) << e.message;  // not the skeleton mesh assimp makes up
}

TEST(Assimp, AMeshLargerThanTheMemoryBudgetIsRefusedBeforeItIsReadIn) {
  const test::ScratchDir dir("assimp");
  const auto path = dir / "cubes.dae";
  test::writeFile(path, colladaCubes(1.0));
  LoadOptions tight;
  tight.memoryBudget = 1000;  // bytes: the 24 triangles need ~3,700
  const Error e = mustFail(path, tight);
  EXPECT_EQ(e.code, ErrorCode::kTooLarge);
  EXPECT_NE(e.message.find("24 triangles"), std::string::npos) << e.message;
}

/// Sets an environment variable for the scope of a test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : mName(name) {
    if (const char* old = std::getenv(name)) mOld = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (mOld)
      ::setenv(mName, mOld->c_str(), 1);
    else
      ::unsetenv(mName);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* mName;
  std::optional<std::string> mOld;
};

TEST(Assimp, AReaderThatCrashesCostsTheFileNotTheProcess) {
  const test::ScratchDir dir("assimp");
  const auto path = dir / "cubes.dae";
  test::writeFile(path, colladaCubes(1.0));
  {
    const ScopedEnv crashing("SHAPEDB_ASSIMP", SHAPEDB_CRASHING_ASSIMP);
    const Error e = mustFail(path);
    EXPECT_EQ(e.code, ErrorCode::kParse);
    // "crashed reading it (Segmentation fault)"; under a sanitizer, whose handler exits instead,
    // "stopped reading it without an answer".
    EXPECT_NE(e.message.find("the file is malformed, or of a kind assimp cannot read"), std::string::npos)
        << e.message;
  }
  {
    const ScopedEnv missing("SHAPEDB_ASSIMP", (dir / "libassimp-nowhere.so").string());
    const Error e = mustFail(path);
    EXPECT_EQ(e.code, ErrorCode::kIo);
    EXPECT_NE(e.message.find("apt-get install libassimp5"), std::string::npos) << e.message;
  }
  // And the next file reads as before.
  expectTwoCubes(mustLoad(path), 1.0);
}

}  // namespace
}  // namespace shapedb::io::assimp_test
