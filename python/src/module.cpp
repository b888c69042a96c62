// The Python module `shapedb` (its compiled part, `shapedb._shapedb`): the library's load, mass
// properties, normalize, describe, database build and query, and fracture, with NumPy arrays in and out.
// python/shapedb/__init__.py re-exports and documents it; README.md ("Using it from Python") shows it in use.
#include <memory>
#include <optional>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <string>
#include <utility>
#include <vector>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/material.h>
#include <shapedb/core/normalize.h>
#include <shapedb/core/topology.h>
#include <shapedb/io/build.h>
#include <shapedb/io/database.h>
#include <shapedb/io/mesh_io.h>
#include <shapedb/volume/describe.h>
#include <shapedb/volume/families.h>
#include <shapedb/volume/fracture.h>
#include <shapedb/volume/modal.h>

#include "arrays.h"

namespace shapedb::python {
namespace {

using namespace pybind11::literals;

// ---- errors ------------------------------------------------------------------------------------------

const char* codeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::kIo:
      return "io";
    case ErrorCode::kUnknownFormat:
      return "unknown_format";
    case ErrorCode::kParse:
      return "parse";
    case ErrorCode::kEmptyMesh:
      return "empty_mesh";
    case ErrorCode::kNonFinite:
      return "non_finite";
    case ErrorCode::kIndexOutOfRange:
      return "index_out_of_range";
    case ErrorCode::kDegenerateFace:
      return "degenerate_face";
    case ErrorCode::kNotClosed:
      return "not_closed";
    case ErrorCode::kNonManifold:
      return "non_manifold";
    case ErrorCode::kInconsistentOrientation:
      return "inconsistent_orientation";
    case ErrorCode::kInsideOut:
      return "inside_out";
    case ErrorCode::kZeroVolume:
      return "zero_volume";
    case ErrorCode::kInvalidArgument:
      return "invalid_argument";
    case ErrorCode::kCancelled:
      return "cancelled";
    case ErrorCode::kTooLarge:
      return "too_large";
    case ErrorCode::kSelfIntersecting:
      return "self_intersecting";
  }
  return "unknown";
}

/// shapedb.Error, created at import and never released (a static py::object would be released after the
/// interpreter is gone).
py::handle& errorType() {
  static py::handle type;
  return type;
}

/// An instance of shapedb.Error carrying shapedb's message and its code ("not_closed", ...).
py::object errorObject(const Error& error) {
  py::object e = errorType()(error.message);
  e.attr("code") = codeName(error.code);
  return e;
}

[[noreturn]] void raise(const Error& error) {
  const py::object e = errorObject(error);
  PyErr_SetObject(errorType().ptr(), e.ptr());
  throw py::error_already_set();
}

template <typename T>
T unwrap(Result<T> result) {
  if (!result) raise(result.error());
  return std::move(result).value();
}

void check(const Status& status) {
  if (!status) raise(status.error());
}

core::TriangleMesh validMesh(const py::object& vertices, const py::object& faces) {
  core::TriangleMesh mesh = toMesh(vertices, faces);
  check(core::validateMesh(mesh));
  return mesh;
}

core::Material toMaterial(const py::object& material) {
  if (py::isinstance<py::str>(material)) return unwrap(core::materialPreset(material.cast<std::string>()));
  if (py::isinstance<py::dict>(material)) {
    const auto d = material.cast<py::dict>();
    core::Material m{.name = "custom",
                     .density = d["density"].cast<double>(),
                     .youngsModulus = d["youngs_modulus"].cast<double>(),
                     .poissonRatio = d.contains("poisson_ratio") ? d["poisson_ratio"].cast<double>() : 0.3};
    check(core::validateMaterial(m));
    return m;
  }
  throw py::type_error(
      "material must be a preset's name ('steel', ...) or a dict with density, "
      "youngs_modulus and poisson_ratio");
}

core::DescriptorKind toKind(const std::string& name) {
  const auto kind = core::parseDescriptorKind(name);
  if (!kind)
    throw py::value_error("descriptor must be 'moment', 'voxel' or 'centroid-voxel', not '" + name + "'");
  return *kind;
}

// ---- small value types, as dicts ----------------------------------------------------------------------

py::dict massPropertiesDict(const core::MassProperties& m) {
  return py::dict("density"_a = m.density, "volume"_a = m.volume, "mass"_a = m.mass, "area"_a = m.area,
                  "center_of_mass"_a = copyOf(m.centerOfMass), "inertia"_a = copyOf(m.inertia),
                  "is_approximate"_a = m.isApproximate);
}

py::dict normalizationDict(const core::Normalization& n) {
  return py::dict(
      "canonical_from_mesh"_a = copyOf(n.canonicalFromMesh),
      "mesh_from_canonical"_a = copyOf(n.meshFromCanonical), "scale"_a = n.scale,
      "principal_axes"_a = copyOf(n.principalAxes), "principal_moments"_a = copyOf(n.principalMoments),
      "canonical_moments"_a = copyOf(n.canonicalMoments), "degeneracy"_a = core::toString(n.degeneracy));
}

py::dict materialDict(const core::Material& m) {
  return py::dict("name"_a = m.name, "density"_a = m.density, "youngs_modulus"_a = m.youngsModulus,
                  "poisson_ratio"_a = m.poissonRatio);
}

py::list collisionList(const core::CollisionCompound& compound) {
  py::list shapes;
  for (const core::CollisionShape& s : compound.shapes) {
    py::dict d("type"_a = core::toString(s.type), "center"_a = copyOf(s.center));
    if (s.type != core::CollisionShape::Type::kSphere) d["rotation"] = copyOf(s.rotation);
    if (s.type == core::CollisionShape::Type::kBox) d["half_extents"] = copyOf(s.halfExtents);
    if (s.type != core::CollisionShape::Type::kBox) d["radius"] = s.radius;
    if (s.type == core::CollisionShape::Type::kCapsule) d["half_length"] = s.halfLength;
    shapes.append(std::move(d));
  }
  return shapes;
}

py::dict fidelityDict(const core::Fidelity& f) {
  return py::dict("descriptor_distance"_a = f.descriptorDistance, "query_moments"_a = copyOf(f.queryMoments),
                  "entry_moments"_a = copyOf(f.entryMoments), "moment_error"_a = copyOf(f.momentError),
                  "max_moment_error"_a = f.maxMomentError, "mean_deviation"_a = f.meanDeviation,
                  "max_deviation"_a = f.maxDeviation, "samples"_a = f.samples);
}

py::dict correctionDict(const volume::CorrectionReport& r) {
  const volume::MorphReport& m = r.morph;
  return py::dict(
      "stretch"_a = copyOf(m.stretch), "entry_worst_quality"_a = m.entryWorstQuality,
      "worst_quality"_a = m.worstQuality, "max_boundary_move"_a = m.maxBoundaryMove,
      "mean_boundary_move"_a = m.meanBoundaryMove, "mean_target_distance"_a = m.meanTargetDistance,
      "projected"_a = m.projected, "mass_scale"_a = r.massScale, "stray_share"_a = r.strayShare,
      "point_mass_peak"_a = r.pointMassPeak, "lumped_mode_share"_a = r.lumpedModeShare,
      "mass_spread"_a = r.massSpread, "solves"_a = r.solves, "morphs"_a = r.morphs, "fallback"_a = r.fallback,
      "morph_seconds"_a = r.morphSeconds, "modes_seconds"_a = r.modesSeconds);
}

py::dict timesDict(const io::QueryTimes& t) {
  return py::dict("validate"_a = t.validate, "mass_properties"_a = t.massProperties,
                  "describe"_a = t.describe, "search"_a = t.search, "fetch"_a = t.fetch,
                  "correct"_a = t.correct, "adapt"_a = t.adapt, "link"_a = t.link, "fidelity"_a = t.fidelity,
                  "total"_a = t.total);
}

py::tuple meshTuple(core::TriangleMesh mesh) {
  py::array_t<std::int64_t> faces = indexArray(mesh.triangles);
  return py::make_tuple(ownedPoints(std::move(mesh.vertices)), std::move(faces));
}

// ---- query results ------------------------------------------------------------------------------------

/// One match, its entry's name and family copied out (the entry record belongs to the database).
struct PyMatch {
  core::Match match;
  std::string name, family;
  std::optional<core::Fidelity> fidelity;
  std::optional<double> predictedError;
};

/// What Database.query returns: the C++ result, shared with every array it hands out.
struct PyQueryResult {
  std::shared_ptr<const io::QueryResult> result;
  std::vector<PyMatch> matches;
};

PyQueryResult wrapResult(io::QueryResult result) {
  PyQueryResult out;
  for (const io::MatchReport& m : result.matches)
    out.matches.push_back({m.match, m.entry ? m.entry->name : std::string(),
                           m.entry ? volume::toString(m.entry->family) : "", m.fidelity,
                           m.predictedFrequencyError});
  out.result = std::make_shared<const io::QueryResult>(std::move(result));
  return out;
}

/// The answer's physical data in the query's frame, size and material (QueryResult.physics).
py::dict physicsDict(const std::shared_ptr<const io::QueryResult>& keep) {
  const core::AdaptedPhysics& p = *keep->physics;
  const auto nodes = static_cast<py::ssize_t>(p.tetMesh.nodeCount());
  const auto modes = static_cast<py::ssize_t>(p.modeShapes.cols());
  // modeShapes is 3·nodes × modes, column-major: mode j, node n, axis c at j·3·nodes + 3n + c.
  py::array shapes =
      view(p.modeShapes.data(), {modes, nodes, 3},
           {static_cast<py::ssize_t>(3 * nodes * sizeof(double)), 3 * sizeof(double), sizeof(double)}, keep);
  return py::dict("material"_a = materialDict(p.material), "mass"_a = p.massProperties.mass,
                  "volume"_a = p.massProperties.volume,
                  "center_of_mass"_a = copyOf(p.massProperties.centerOfMass),
                  "inertia"_a = copyOf(p.massProperties.inertia), "entry_mass"_a = p.entryMassProperties.mass,
                  "frequencies"_a = copyOf(p.frequenciesHz()), "eigenvalues"_a = copyOf(p.eigenvalues),
                  "damping_ratios"_a = copyOf(p.dampingRatios()), "mode_shapes"_a = std::move(shapes),
                  "tet_nodes"_a = pointsView(p.tetMesh.nodes, keep), "tets"_a = indexArray(p.tetMesh.tets),
                  "collision"_a = collisionList(p.collision), "warnings"_a = p.warnings,
                  "spectrum_weights"_a = keep->spectrumWeights);
}

/// The query's vertices in the answer's tets (QueryResult.link): per vertex its tet, its four weights and
/// its distance outside (0 inside), views into the link.
py::dict linkDict(const std::shared_ptr<const io::QueryResult>& keep) {
  const core::SurfaceLink& link = keep->link;
  const auto n = static_cast<py::ssize_t>(link.locations.size());
  const auto stride = static_cast<py::ssize_t>(sizeof(core::TetLocation));
  const core::TetLocation* first = link.locations.empty() ? nullptr : link.locations.data();
  const auto member = [&](auto pointer) { return first ? &(first->*pointer) : nullptr; };
  return py::dict("tets"_a = view(member(&core::TetLocation::tet), {n}, {stride}, keep),
                  "weights"_a = view(first ? member(&core::TetLocation::weights)->data() : nullptr, {n, 4},
                                     {stride, sizeof(double)}, keep),
                  "distances"_a = view(member(&core::TetLocation::distance), {n}, {stride}, keep),
                  "outside_count"_a = link.outsideCount, "max_outside_distance"_a = link.maxOutsideDistance);
}

// ---- the database -------------------------------------------------------------------------------------

/// Database(path): the C++ Database behind a shared_ptr, so that a query running without the GIL keeps
/// it alive even if the Python object is closed meanwhile.
class PyDatabase {
 public:
  /// `descriptors`: the kinds whose indexes to build (None: all three); a query by another is an error.
  PyDatabase(const std::string& path, std::size_t cacheEntries,
             const std::optional<std::vector<std::string>>& descriptors)
      : mPath(path) {
    io::Database::OpenOptions options;
    options.cacheEntries = cacheEntries;
    if (descriptors) {
      options.descriptors.clear();
      for (const std::string& name : *descriptors)
        options.descriptors.push_back(toKind(name));
    }
    Result<io::Database> db = [&] {
      py::gil_scoped_release release;
      return io::Database::open(path, options);
    }();
    mDb = std::make_shared<const io::Database>(unwrap(std::move(db)));
  }

  std::shared_ptr<const io::Database> get() const {
    if (!mDb) throw py::value_error(mPath + ": the database is closed");
    return mDb;
  }
  void close() { mDb.reset(); }
  std::size_t size() const { return get()->size(); }

  PyQueryResult query(const py::object& vertices, const py::object& faces,
                      const io::QueryOptions& options) const {
    const core::TriangleMesh mesh = toMesh(vertices, faces);
    const std::shared_ptr<const io::Database> db = get();
    Result<io::QueryResult> result = [&] {
      py::gil_scoped_release release;
      return db->query(mesh, options);
    }();
    return wrapResult(unwrap(std::move(result)));
  }

  /// Results in input order; a mesh that failed has its shapedb.Error in its slot.
  py::list queryMany(const py::iterable& meshes, const io::QueryOptions& options) const {
    std::vector<core::TriangleMesh> surfaces;
    for (const py::handle& item : meshes) {
      if (!py::isinstance<py::sequence>(item))
        throw py::type_error("query_many takes (vertices, faces) pairs");
      const auto pair = item.cast<py::sequence>();
      if (pair.size() != 2) throw py::value_error("query_many takes (vertices, faces) pairs");
      surfaces.push_back(toMesh(pair[0], pair[1]));
    }
    const std::shared_ptr<const io::Database> db = get();
    std::vector<Result<io::QueryResult>> results;
    {
      py::gil_scoped_release release;
      results = db->queryMany(surfaces, options);
    }
    py::list out;
    for (Result<io::QueryResult>& r : results)
      out.append(r ? py::cast(wrapResult(std::move(r).value())) : errorObject(r.error()));
    return out;
  }

  py::dict info() const {
    const std::shared_ptr<const io::Database> db = get();
    py::dict families;
    for (const io::EntryRecord& e : db->entries()) {
      const py::str family(volume::toString(e.family));
      families[family] = families.contains(family) ? families[family].cast<std::size_t>() + 1 : 1;
    }
    const py::object parameters = py::module_::import("json").attr("loads")(io::toJson(db->parameters()));
    return py::dict("path"_a = mPath, "entries"_a = db->entries().size(),
                    "learned"_a = db->learnedEntries().size(), "families"_a = families,
                    "parameters"_a = parameters);
  }

 private:
  std::string mPath;
  std::shared_ptr<const io::Database> mDb;
};

io::QueryOptions queryOptions(int k, const std::string& descriptor, const py::object& material, bool correct,
                              bool fidelity, bool approximate, bool adapt, int candidates, int neighbours) {
  if (k < 1) throw py::value_error("k must be at least 1, not " + std::to_string(k));
  if (candidates < 1 || candidates > io::kMaxCorrectionCandidates)
    throw py::value_error("correction_candidates must be 1 to " +
                          std::to_string(io::kMaxCorrectionCandidates) + ", not " +
                          std::to_string(candidates));
  if (neighbours < 1 || neighbours > 100)
    throw py::value_error("neighbours must be 1 to 100, not " + std::to_string(neighbours));
  io::QueryOptions o;
  o.search.k = k;
  o.descriptor = toKind(descriptor);
  o.material = toMaterial(material);
  o.correct = correct;
  o.fidelity = fidelity;
  o.approximate = approximate;
  o.adapt = adapt;
  o.link = adapt;
  o.correctionCandidates = candidates;
  o.neighbours = neighbours;
  return o;
}

// ---- module-level functions ---------------------------------------------------------------------------

py::tuple loadMesh(const std::string& path, double scale, bool keepSpecks) {
  io::LoadOptions options;
  options.scale = scale;
  options.dropSpecks = !keepSpecks;
  Result<io::LoadedMesh> loaded = [&] {
    py::gil_scoped_release release;
    return io::loadMesh(path, options);
  }();
  io::LoadedMesh mesh = unwrap(std::move(loaded));
  // What was done to the file's surface (flipped, welded, faces dropped) as Python warnings, named.
  for (const std::string& note : mesh.notes())
    if (PyErr_WarnEx(PyExc_UserWarning, (path + ": " + note).c_str(), 1) != 0) throw py::error_already_set();
  return meshTuple(std::move(mesh.mesh));
}

core::MassProperties massOf(const core::TriangleMesh& mesh, double density, bool approximate) {
  core::MassPropertiesOptions options;
  options.density = density;
  options.allowApproximate = approximate;
  return unwrap(core::computeMassProperties(mesh, options));
}

py::dict describe(const py::object& vertices, const py::object& faces, const std::string& kind, int grid,
                  const std::string& sampling) {
  const core::TriangleMesh mesh = validMesh(vertices, faces);
  core::DescriptorOptions options;
  options.kind = toKind(kind);
  options.gridSize = grid;
  const auto s = core::parseSampling(sampling);
  if (!s) throw py::value_error("sampling must be 'area' or 'vertex', not '" + sampling + "'");
  options.sampling = *s;
  const core::Normalization frame = unwrap(core::normalize(mesh, massOf(mesh, 1.0, false)));
  auto d = std::make_shared<const core::Descriptor>(unwrap(volume::describe(mesh, frame, options)));
  const auto cells = static_cast<py::ssize_t>(d->cells.size());
  return py::dict(
      "kind"_a = core::toString(d->kind), "moments"_a = copyOf(d->moments), "grid_size"_a = d->gridSize,
      "cell_size"_a = d->cellSize, "cells"_a = view(d->cells.data(), {cells}, {sizeof(std::uint32_t)}, d),
      "centroids"_a = pointsView(d->centroids, d),
      "weights"_a =
          view(d->weights.data(), {static_cast<py::ssize_t>(d->weights.size())}, {sizeof(double)}, d));
}

py::dict build(const std::string& path, std::size_t entries, const std::string& families,
               const std::string& elements, int modes, int threads, bool resume) {
  io::BuildOptions options;
  options.threads = threads;
  options.resume = resume;
  io::BuildParameters& p = options.parameters;
  p.entries = entries;
  volume::FamilyMix mix = unwrap(volume::parseFamilyMix(families));
  p.families = std::move(mix.families);
  p.weights = std::move(mix.weights);
  const auto order = volume::parseElementOrder(elements);
  if (!order) throw py::value_error("elements must be 'linear' or 'quadratic', not '" + elements + "'");
  p = io::withElements(p, *order);
  p.entry.modal.modes = modes;
  Result<io::BuildReport> report = [&] {
    py::gil_scoped_release release;
    return io::buildDatabase(path, options);
  }();
  const io::BuildReport r = unwrap(std::move(report));
  return py::dict("built"_a = r.built, "failed"_a = r.failed, "skipped"_a = r.skipped,
                  "seconds"_a = r.seconds);
}

py::dict fracture(const py::object& vertices, const py::object& faces, int pieces, std::uint64_t seed,
                  int resolution, std::size_t maxTriangles) {
  const core::TriangleMesh mesh = validMesh(vertices, faces);
  volume::FractureOptions options;
  options.pieces = pieces;
  options.seed = seed;
  options.resolution = resolution;
  options.maxTriangles = maxTriangles;
  Result<volume::FractureResult> broken = [&] {
    py::gil_scoped_release release;
    return volume::fracture(mesh, options);
  }();
  volume::FractureResult r = unwrap(std::move(broken));
  py::list fragments;
  for (core::TriangleMesh& f : r.fragments)
    fragments.append(meshTuple(std::move(f)));
  return py::dict("fragments"_a = fragments, "solid_volume"_a = r.solidVolume, "kept_volume"_a = r.keptVolume,
                  "kept_fraction"_a = r.keptFraction(), "dropped_volume"_a = r.droppedVolume,
                  "crumbs_dropped"_a = r.crumbsDropped, "resolution"_a = r.resolution,
                  "voxel_size"_a = r.voxelSize);
}

}  // namespace
}  // namespace shapedb::python

PYBIND11_MODULE(_shapedb, m) {
  using namespace shapedb;
  using namespace shapedb::python;
  namespace py = pybind11;
  using namespace pybind11::literals;
  m.doc() = "shapedb's compiled core; import shapedb, which documents it.";
  errorType() = py::exception<std::runtime_error>(m, "Error", PyExc_RuntimeError).inc_ref();
  errorType().attr("__doc__") =
      "A failure of shapedb itself: its message names the file or the problem; .code names the kind "
      "('io', 'not_closed', 'invalid_argument', ...).";
  errorType().attr("code") = "unknown";

  m.def("load_mesh", &loadMesh,
        "(V, F) of an OBJ, PLY, OFF, STL, glTF (.gltf, .glb), FBX or COLLADA (.dae) file; coordinates times "
        "`scale` (the file's "
        "unit in metres); detached parts under 0.001 of the largest part's area are dropped unless "
        "keep_specks.",
        "path"_a, py::kw_only(), "scale"_a = 1.0, "keep_specks"_a = false);
  m.def(
      "save_mesh",
      [](const std::string& path, const py::object& v, const py::object& f, bool binary) {
        const core::TriangleMesh mesh = toMesh(v, f);
        const Status saved = [&] {
          py::gil_scoped_release release;  // the error is raised with the GIL held
          return io::saveMesh(mesh, path, {.binary = binary});
        }();
        check(saved);
      },
      "Writes (V, F) as OBJ or PLY (double precision: load_mesh reads back the same vertices) or glTF "
      "(.glb, .gltf: single precision about the mesh's centre, for a game engine), by extension.",
      "path"_a, "vertices"_a, "faces"_a, py::kw_only(), "binary"_a = true);
  m.def(
      "mass_properties",
      [](const py::object& v, const py::object& f, double density, bool approximate) {
        return massPropertiesDict(massOf(validMesh(v, f), density, approximate));
      },
      "Exact volume, mass, area, centre of mass and inertia (about the centre of mass) of the solid the "
      "surface encloses; approximate=True accepts an open surface (vertex point masses).",
      "vertices"_a, "faces"_a, py::kw_only(), "density"_a = 1.0, "approximate"_a = false);
  m.def(
      "normalize",
      [](const py::object& v, const py::object& f) {
        const core::TriangleMesh mesh = validMesh(v, f);
        return normalizationDict(unwrap(core::normalize(mesh, massOf(mesh, 1.0, false))));
      },
      "The canonical frame: canonical_from_mesh (4x4, to unit volume about the centre of mass, principal "
      "axes "
      "along x, y, z), its inverse, the scale and the principal moments.",
      "vertices"_a, "faces"_a);
  m.def("describe", &describe,
        "The descriptor a database searches by: filled cells, their surface centroids (in the cell's unit "
        "cube) "
        "and weights, and the canonical moments.",
        "vertices"_a, "faces"_a, py::kw_only(), "kind"_a = "centroid-voxel", "grid"_a = 10,
        "sampling"_a = "area");
  m.def("build", &build,
        "Builds (or, with resume, finishes) a database file; families as 'box,fragment:3'. Releases the GIL.",
        "path"_a, py::kw_only(), "entries"_a = io::BuildParameters{}.entries, "families"_a = "all",
        "elements"_a = "quadratic", "modes"_a = 20, "threads"_a = 0, "resume"_a = false);
  m.def(
      "fracture", &fracture,
      "Breaks a closed surface into fragments: a dict with 'fragments' (a list of (V, F), largest first) and "
      "the volume kept. Releases the GIL.",
      "vertices"_a, "faces"_a, py::kw_only(), "pieces"_a = 20, "seed"_a = 1, "resolution"_a = 0,
      "max_triangles"_a = 3000);
  m.def(
      "materials",
      [] {
        std::vector<std::string> names;
        for (const core::Material& material : core::materialPresets())
          names.push_back(material.name);
        return names;
      },
      "The material presets' names.");
  m.def(
      "families",
      [] {
        std::vector<std::string> names;
        for (volume::Family family : volume::defaultFamilyMix().families)
          names.push_back(volume::toString(family));
        return names;
      },
      "The catalog's shape families.");

  py::class_<PyMatch>(m, "Match")
      .def_property_readonly("entry_id", [](const PyMatch& x) { return x.match.entry; })
      .def_readonly("name", &PyMatch::name)
      .def_readonly("family", &PyMatch::family)
      .def_property_readonly("distance", [](const PyMatch& x) { return x.match.distance; })
      .def_property_readonly("moment_term", [](const PyMatch& x) { return x.match.momentTerm; })
      .def_property_readonly("orientation", [](const PyMatch& x) { return copyOf(x.match.orientation); })
      .def_property_readonly("fidelity",
                             [](const PyMatch& x) -> py::object {
                               return x.fidelity ? py::object(fidelityDict(*x.fidelity)) : py::none();
                             })
      .def_readonly("predicted_frequency_error", &PyMatch::predictedError)
      .def("__repr__", [](const PyMatch& x) {
        return "<shapedb.Match " + x.name + " distance " + std::to_string(x.match.distance) + ">";
      });

  py::class_<PyQueryResult>(m, "QueryResult")
      .def_readonly("matches", &PyQueryResult::matches)
      .def_property_readonly("answered", [](const PyQueryResult& x) { return x.result->answered; })
      .def_property_readonly("match", [](const PyQueryResult& x) { return x.matches.at(x.result->answered); })
      .def_property_readonly(
          "mass_properties",
          [](const PyQueryResult& x) { return massPropertiesDict(x.result->massProperties); })
      .def_property_readonly(
          "normalization", [](const PyQueryResult& x) { return normalizationDict(x.result->normalization); })
      .def_property_readonly("physics",
                             [](const PyQueryResult& x) -> py::object {
                               return x.result->physics ? py::object(physicsDict(x.result)) : py::none();
                             })
      .def_property_readonly("link",
                             [](const PyQueryResult& x) -> py::object {
                               return x.result->link.locations.empty() ? py::none()
                                                                       : py::object(linkDict(x.result));
                             })
      .def_property_readonly("correction",
                             [](const PyQueryResult& x) -> py::object {
                               return x.result->correction ? py::object(correctionDict(*x.result->correction))
                                                           : py::none();
                             })
      .def_property_readonly("predicted_frequency_error",
                             [](const PyQueryResult& x) { return x.result->predictedFrequencyError; })
      .def_property_readonly("orientation_candidates",
                             [](const PyQueryResult& x) { return x.result->orientationCandidates; })
      .def_property_readonly("times_us", [](const PyQueryResult& x) { return timesDict(x.result->times); });

  py::class_<PyDatabase>(m, "Database")
      .def(py::init<const std::string&, std::size_t, const std::optional<std::vector<std::string>>&>(),
           "path"_a, py::kw_only(), "cache_entries"_a = io::Database::OpenOptions{}.cacheEntries,
           "descriptors"_a = py::none())
      .def(
          "query",
          [](const PyDatabase& db, const py::object& v, const py::object& f, int k,
             const std::string& descriptor, const py::object& material, bool correct, bool fidelity,
             bool approximate, bool adapt, int candidates, int neighbours) {
            return db.query(v, f,
                            queryOptions(k, descriptor, material, correct, fidelity, approximate, adapt,
                                         candidates, neighbours));
          },
          "vertices"_a, "faces"_a, py::kw_only(), "k"_a = 1, "descriptor"_a = "centroid-voxel",
          "material"_a = "steel", "correct"_a = false, "fidelity"_a = true, "approximate"_a = false,
          "adapt"_a = true, "correction_candidates"_a = io::QueryOptions{}.correctionCandidates,
          "neighbours"_a = io::QueryOptions{}.neighbours)
      .def(
          "query_many",
          [](const PyDatabase& db, const py::iterable& meshes, int k, const std::string& descriptor,
             const py::object& material, bool correct, bool fidelity, bool approximate, bool adapt,
             int candidates, int neighbours) {
            return db.queryMany(meshes, queryOptions(k, descriptor, material, correct, fidelity, approximate,
                                                     adapt, candidates, neighbours));
          },
          "meshes"_a, py::kw_only(), "k"_a = 1, "descriptor"_a = "centroid-voxel", "material"_a = "steel",
          "correct"_a = false, "fidelity"_a = true, "approximate"_a = false, "adapt"_a = true,
          "correction_candidates"_a = io::QueryOptions{}.correctionCandidates,
          "neighbours"_a = io::QueryOptions{}.neighbours)
      .def("info", &PyDatabase::info)
      .def("close", &PyDatabase::close)
      .def("__len__", &PyDatabase::size)
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PyDatabase& db, const py::args&) { db.close(); });
}
