#pragma once
// NumPy arrays in and out of shapedb's types, for the Python module.
//
// Out: an array is a view into the C++ value it comes from wherever its layout allows (vertices, mode
// shapes, a link's weights), and that value is kept alive by the array itself (its base is a capsule
// holding a shared_ptr), so an array outlives the result or database object that handed it out. Views
// into results are read-only: the result is shared. Small fixed-size values (3×3 matrices) are copied.
//
// In: vertices as any real (n, 3) array, converted to float64; faces as any integer (m, 3) array. A
// wrong shape or dtype is a TypeError or ValueError naming the argument, not a crash.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <string>
#include <vector>

#include <shapedb/core/triangle_mesh.h>
#include <shapedb/core/types.h>

namespace shapedb::python {

namespace py = pybind11;

/// A capsule that owns `keep` (any shared_ptr): the base of arrays that view into what it points to.
inline py::capsule keeper(std::shared_ptr<const void> keep) {
  auto* owner = new std::shared_ptr<const void>(std::move(keep));
  return py::capsule(owner, [](void* p) { delete static_cast<std::shared_ptr<const void>*>(p); });
}

/// A read-only view of `data` (kept alive by `keep`) with the given shape and byte strides.
template <typename T>
py::array view(const T* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
               const std::shared_ptr<const void>& keep) {
  py::array out(py::dtype::of<T>(), std::move(shape), std::move(strides), data, keeper(keep));
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

/// Points as an (n, 3) float64 view: Vec3 is three packed doubles.
inline py::array pointsView(const std::vector<core::Vec3>& points, const std::shared_ptr<const void>& keep) {
  static_assert(sizeof(core::Vec3) == 3 * sizeof(double));
  return view(points.empty() ? nullptr : points.front().data(), {static_cast<py::ssize_t>(points.size()), 3},
              {static_cast<py::ssize_t>(sizeof(core::Vec3)), sizeof(double)}, keep);
}

/// Points moved into an (n, 3) float64 array that owns them (writable: nothing else holds them).
inline py::array ownedPoints(std::vector<core::Vec3> points) {
  auto held = std::make_shared<std::vector<core::Vec3>>(std::move(points));
  py::array out = pointsView(*held, held);
  py::detail::array_proxy(out.ptr())->flags |= py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

/// Index tuples (triangles, tets) as an (m, N) int64 array: NumPy's default integer, a copy.
template <std::size_t N>
py::array_t<std::int64_t> indexArray(const std::vector<std::array<std::uint32_t, N>>& rows) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(N)});
  auto w = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < N; ++j)
      w(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(j)) = rows[i][j];
  return out;
}

/// A fixed-size Eigen matrix or vector, copied (row-major in NumPy's sense: out[i, j] = m(i, j)).
template <typename Derived>
py::array_t<double> copyOf(const Eigen::MatrixBase<Derived>& m) {
  if (m.cols() == 1) {
    py::array_t<double> out(static_cast<py::ssize_t>(m.rows()));
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      out.mutable_at(i) = m(i);
    return out;
  }
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      out.mutable_at(i, j) = m(i, j);
  return out;
}

/// The dtype's kind as NumPy names it: 'f' float, 'i' signed, 'u' unsigned, 'b' bool, ...
inline char kindOf(const py::array& a) {
  return a.dtype().kind();
}

inline std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d)
    s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// A surface from NumPy: `vertices` (n, 3) real, `faces` (m, 3) integer, indices in [0, n).
inline core::TriangleMesh toMesh(const py::handle& vertices, const py::handle& faces) {
  const py::array v = py::array::ensure(vertices);
  const py::array f = py::array::ensure(faces);
  if (!v || (kindOf(v) != 'f' && kindOf(v) != 'i' && kindOf(v) != 'u'))
    throw py::type_error("vertices must be a real (n, 3) array (float64 preferred), got dtype " +
                         (v ? std::string(py::str(v.dtype())) : std::string("of a non-array")));
  if (!f || (kindOf(f) != 'i' && kindOf(f) != 'u'))
    throw py::type_error("faces must be an integer (m, 3) array, got dtype " +
                         (f ? std::string(py::str(f.dtype())) : std::string("of a non-array")));
  if (v.ndim() != 2 || v.shape(1) != 3)
    throw py::value_error("vertices must have shape (n, 3), not " + shapeText(v));
  if (f.ndim() != 2 || f.shape(1) != 3)
    throw py::value_error("faces must have shape (m, 3), not " + shapeText(f));
  const auto coordinates = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
  const auto indices = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(f);
  core::TriangleMesh mesh;
  mesh.vertices.resize(static_cast<std::size_t>(v.shape(0)));
  const double* x = coordinates.data();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    mesh.vertices[i] = core::Vec3(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
  mesh.triangles.resize(static_cast<std::size_t>(f.shape(0)));
  const std::int64_t* t = indices.data();
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (std::size_t j = 0; j < 3; ++j) {
      const std::int64_t index = t[3 * i + j];
      // Past the vertices but representable: validateMesh names it (kIndexOutOfRange).
      if (index < 0 || index > std::numeric_limits<std::uint32_t>::max())
        throw py::value_error("faces[" + std::to_string(i) + ", " + std::to_string(j) +
                              "] = " + std::to_string(index) + " is not a vertex index");
      mesh.triangles[i][j] = static_cast<std::uint32_t>(index);
    }
  return mesh;
}

}  // namespace shapedb::python
