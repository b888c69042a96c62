// Ten thin-walled shapes outside the catalog's ranges (the family generators with other parameters), written
// as OBJ files into the folder given: the shapes of thin10.csv. Built against the library with
//   add_executable(thinshapes PATH/thinshapes.cpp) + target_link_libraries(thinshapes PRIVATE shapedb::io)
#include <cstdio>
#include <string>

#include <shapedb/core/mass_properties.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/families.h>
using namespace shapedb;
int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : ".";
  struct S {
    const char* name;
    volume::Family family;
    std::uint32_t index;
    core::Vec3 params;
  };
  const S shapes[] = {
      {"plate_holes1_t30", volume::Family::kHoled, 0, {1.0, 1.0 / 30, 1}},
      {"plate_holes2_t50", volume::Family::kHoled, 2, {0.7, 1.0 / 50, 2}},
      {"plate_holes3_t40", volume::Family::kHoled, 5, {0.5, 1.0 / 40, 3}},
      {"plate_holes4_t60", volume::Family::kHoled, 7, {1.0, 1.0 / 60, 4}},
      {"plate_holes6_t35", volume::Family::kHoled, 2, {0.8, 1.0 / 35, 6}},
      {"plate_holes5_t80", volume::Family::kHoled, 4, {0.6, 1.0 / 80, 5}},
      {"tray_rim_a", volume::Family::kShell, 3, {0.12, 0.03, 1.2}},
      {"tray_rim_b", volume::Family::kShell, 3, {0.08, 0.025, 0.8}},
      {"dish_bowl", volume::Family::kShell, 1, {0.15, 0.03, 0.0}},
      {"dish_cup", volume::Family::kShell, 0, {0.1, 0.03, 0.0}},
  };
  for (const S& s : shapes) {
    volume::ShapeSpec spec;
    spec.family = s.family;
    spec.index = s.index;
    spec.params = s.params;
    auto mesh = volume::makeFamilyShape(spec, {});
    if (!mesh) {
      std::printf("%s: %s\n", s.name, mesh.error().message.c_str());
      continue;
    }
    core::Vec3 lo = mesh->vertices[0], hi = lo;
    for (auto& v : mesh->vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    auto st = io::saveMesh(*mesh, out + "/" + s.name + ".obj");
    std::printf("%s: %zu triangles, extent %.3f %.3f %.3f %s\n", s.name, mesh->triangles.size(),
                hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z(), st ? "" : st.error().message.c_str());
  }
}
