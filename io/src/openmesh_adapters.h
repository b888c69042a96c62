#pragma once

// The adapter between OpenMesh's file readers and shapedb's TriangleMesh. OpenMesh's own mesh kernels
// reject non-manifold faces while reading; this importer keeps every face exactly as the file has it,
// so that topology is judged by shapedb (analyzeTopology), not silently repaired.

#include <cstdint>
#include <vector>

#include <OpenMesh/Core/IO/importer/BaseImporter.hh>

#include "raw_polygons.h"

namespace shapedb::io::detail {

/// Collects vertices and polygons from an OpenMesh reader, unchanged. One per read.
class RawImporter final : public OpenMesh::IO::BaseImporter {
 public:
  using VH = OpenMesh::VertexHandle;
  using FH = OpenMesh::FaceHandle;
  using HH = OpenMesh::HalfedgeHandle;
  using EH = OpenMesh::EdgeHandle;

  RawPolygons raw;

  VH add_vertex(const OpenMesh::Vec3f& p) override { return add_vertex(OpenMesh::Vec3d(p)); }
  VH add_vertex(const OpenMesh::Vec3d& p) override {
    raw.vertices.emplace_back(p[0], p[1], p[2]);
    return VH(static_cast<int>(raw.vertices.size() - 1));
  }
  VH add_vertex() override { return add_vertex(OpenMesh::Vec3d(0.0, 0.0, 0.0)); }
  void set_point(VH vh, const OpenMesh::Vec3f& p) override {
    if (vh.is_valid() && static_cast<std::size_t>(vh.idx()) < raw.vertices.size())
      raw.vertices[static_cast<std::size_t>(vh.idx())] = core::Vec3(p[0], p[1], p[2]);
  }
  FH add_face(const VHandles& indices) override {
    for (const VH& vh : indices)
      raw.corners.push_back(vh.idx() < 0 ? RawPolygons::kInvalidIndex : static_cast<std::uint32_t>(vh.idx()));
    raw.endPolygon();
    return FH(static_cast<int>(raw.polygonCount() - 1));
  }
  FH add_face(HH) override { return FH(); }
  HH add_edge(VH, VH) override { return HH(); }
  std::size_t n_vertices() const override { return raw.vertices.size(); }
  std::size_t n_faces() const override { return raw.polygonCount(); }
  std::size_t n_edges() const override { return 0; }
  // Reserve requests come from file headers, which may lie: never allocate on their word.
  void reserve(unsigned int, unsigned int, unsigned int) override {}

  // Attributes shapedb does not use.
  void add_face_texcoords(FH, VH, const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(FH, VH, const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(FH, int) override {}
  void set_halfedge(VH, HH) override {}
  void set_normal(VH, const OpenMesh::Vec3f&) override {}
  void set_normal(VH, const OpenMesh::Vec3d&) override {}
  void set_color(VH, const OpenMesh::Vec3uc&) override {}
  void set_color(VH, const OpenMesh::Vec4uc&) override {}
  void set_color(VH, const OpenMesh::Vec3f&) override {}
  void set_color(VH, const OpenMesh::Vec4f&) override {}
  void set_texcoord(VH, const OpenMesh::Vec2f&) override {}
  void set_status(VH, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_next(HH, HH) override {}
  void set_face(HH, FH) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HH, const OpenMesh::Vec2f&) override {}
  void set_texcoord(VH, const OpenMesh::Vec3f&) override {}
  void set_texcoord(HH, const OpenMesh::Vec3f&) override {}
  void set_status(HH, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_color(EH, const OpenMesh::Vec3uc&) override {}
  void set_color(EH, const OpenMesh::Vec4uc&) override {}
  void set_color(EH, const OpenMesh::Vec3f&) override {}
  void set_color(EH, const OpenMesh::Vec4f&) override {}
  void set_status(EH, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_normal(FH, const OpenMesh::Vec3f&) override {}
  void set_normal(FH, const OpenMesh::Vec3d&) override {}
  void set_color(FH, const OpenMesh::Vec3uc&) override {}
  void set_color(FH, const OpenMesh::Vec4uc&) override {}
  void set_color(FH, const OpenMesh::Vec3f&) override {}
  void set_color(FH, const OpenMesh::Vec4f&) override {}
  void set_status(FH, const OpenMesh::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
};

}  // namespace shapedb::io::detail
