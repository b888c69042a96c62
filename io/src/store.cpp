#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>

#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include <shapedb/core/descriptor.h>
#include <shapedb/io/store.h>

#include "codec.h"

namespace shapedb::io {
namespace {

using nlohmann::json;

/// "SHDB": PRAGMA application_id of every shapedb file, so another application's SQLite file is told apart.
constexpr std::int32_t kApplicationId = 0x53484442;

enum class Part : int { kTetMesh = 0, kMassProperties = 1, kModes = 2, kCollision = 3, kSound = 4 };
constexpr std::array<const char*, 5> kPartNames = {"tet mesh", "mass properties", "modes", "collision",
                                                   "sound"};

/// The largest string or blob a file may hold: an entry's modes (20 modes of a 10k-node tet mesh in 16
/// bits are 1.2 MB) with room to spare.
constexpr int kMaxValueBytes = 256 << 20;

/// The schema objects shapedb creates: its tables and the indexes SQLite makes for their keys. A file
/// with anything else (a trigger, a view, a table or index of its own) did not come from shapedb as it
/// was, and a trigger or view is code that would run inside our queries.
bool isOurSchemaObject(const std::string& type, const std::string& name) {
  static constexpr std::array kTables = {"meta", "entries", "descriptors", "physics", "failures"};
  if (type == "table") return std::find(kTables.begin(), kTables.end(), name) != kTables.end();
  if (type == "index")
    for (const char* table : kTables)
      if (name.rfind(std::string("sqlite_autoindex_") + table + "_", 0) == 0) return true;
  return false;
}

const char* kSchema = R"sql(
CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE entries(
  id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, family TEXT NOT NULL, params TEXT NOT NULL,
  source TEXT NOT NULL, nodes INTEGER NOT NULL, tets INTEGER NOT NULL, times TEXT NOT NULL);
CREATE TABLE descriptors(
  entry_id INTEGER NOT NULL REFERENCES entries(id), kind INTEGER NOT NULL, data BLOB NOT NULL,
  checksum INTEGER NOT NULL, PRIMARY KEY(entry_id, kind));
CREATE TABLE physics(
  entry_id INTEGER NOT NULL REFERENCES entries(id), part INTEGER NOT NULL, data BLOB NOT NULL,
  checksum INTEGER NOT NULL, PRIMARY KEY(entry_id, part));
CREATE TABLE failures(name TEXT PRIMARY KEY, message TEXT NOT NULL);
)sql";

/// A prepared statement that finalizes itself.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) { mRc = sqlite3_prepare_v2(db, sql, -1, &mStmt, nullptr); }
  ~Statement() { sqlite3_finalize(mStmt); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return mRc == SQLITE_OK; }
  sqlite3_stmt* get() const { return mStmt; }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(mStmt, i, v); }
  void bind(int i, double v) { sqlite3_bind_double(mStmt, i, v); }
  void bind(int i, const std::string& v) {
    sqlite3_bind_text(mStmt, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void bind(int i, const Bytes& v) { sqlite3_bind_blob64(mStmt, i, v.data(), v.size(), SQLITE_TRANSIENT); }
  int step() { return sqlite3_step(mStmt); }
  void reset() {
    sqlite3_reset(mStmt);
    sqlite3_clear_bindings(mStmt);
  }
  std::int64_t integer(int column) const { return sqlite3_column_int64(mStmt, column); }
  double real(int column) const { return sqlite3_column_double(mStmt, column); }
  std::string text(int column) const {
    const auto* p = sqlite3_column_text(mStmt, column);
    return p ? std::string(reinterpret_cast<const char*>(p),
                           static_cast<std::size_t>(sqlite3_column_bytes(mStmt, column)))
             : "";
  }
  const void* blob(int column) const { return sqlite3_column_blob(mStmt, column); }
  std::size_t blobSize(int column) const {
    return static_cast<std::size_t>(sqlite3_column_bytes(mStmt, column));
  }

 private:
  sqlite3_stmt* mStmt = nullptr;
  int mRc;
};

json timesToJson(const volume::StageTimes& t) {
  return {{"normalize", t.normalize},
          {"tetrahedralize", t.tetrahedralize},
          {"describe", t.describe},
          {"modes", t.modes},
          {"collision", t.collision}};
}

volume::StageTimes timesFromJson(const json& j) {
  volume::StageTimes t;
  t.normalize = j.value("normalize", 0.0);
  t.tetrahedralize = j.value("tetrahedralize", 0.0);
  t.describe = j.value("describe", 0.0);
  t.modes = j.value("modes", 0.0);
  t.collision = j.value("collision", 0.0);
  return t;
}

}  // namespace

volume::ShapeResolution entryResolution(volume::ElementOrder order) {
  return order == volume::ElementOrder::kQuadratic
             ? volume::ShapeResolution{.segments = 12,
                                       .stacks = 6,
                                       .unionTrianglesPerSegment = 12,
                                       .stoneSubdivisions = 1}
             : volume::ShapeResolution{.segments = 24, .stacks = 12, .stoneSubdivisions = 2};
}

FamilyVolumeFractions entryVolumeFractions(volume::ElementOrder order) {
  if (order == volume::ElementOrder::kQuadratic) return {{volume::Family::kStone, 3.0 / 100.0}};
  return {};
}

BuildParameters withElements(BuildParameters parameters, volume::ElementOrder order) {
  parameters.entry = volume::withElements(parameters.entry, order);
  parameters.resolution = entryResolution(order);
  parameters.volumeFractions = entryVolumeFractions(order);
  return parameters;
}

volume::EntryOptions entryOptionsFor(const BuildParameters& parameters, volume::Family family) {
  volume::EntryOptions options = parameters.entry;
  if (const auto own = parameters.volumeFractions.find(family); own != parameters.volumeFractions.end())
    options.tetgen.maxVolumeFraction = own->second;
  return options;
}

std::string toJson(const BuildParameters& p) {
  const volume::EntryOptions& e = p.entry;
  json families = json::array();
  for (volume::Family f : p.families)
    families.push_back(volume::toString(f));
  json volumeFractions = json::object();
  for (const auto& [family, fraction] : p.volumeFractions)
    volumeFractions[volume::toString(family)] = fraction;
  const json j = {
      {"entries", p.entries},
      {"families", families},
      {"weights", p.weights},
      {"resolution",
       {{"segments", p.resolution.segments},
        {"stacks", p.resolution.stacks},
        {"stone_subdivisions", p.resolution.stoneSubdivisions},
        {"union_triangles_per_segment", p.resolution.unionTrianglesPerSegment}}},
      {"descriptor",
       {{"grid", e.descriptor.gridSize},
        {"sampling", core::toString(e.descriptor.sampling)},
        {"min_cell_area", e.descriptor.minCellArea}}},
      {"tetgen",
       {{"max_radius_edge_ratio", e.tetgen.maxRadiusEdgeRatio},
        {"max_volume_fraction", e.tetgen.maxVolumeFraction},
        {"wall_edge_fraction", e.tetgen.wallEdgeFraction},
        {"family_volume_fractions", volumeFractions}}},
      {"modes",
       {{"count", e.modal.modes},
        {"poisson_ratio", e.modal.material.poissonRatio},
        {"elements", volume::toString(e.modal.order)}}},
      {"collision",
       {{"max_shapes", e.collision.maxShapes},
        {"target_coverage", e.collision.targetCoverage},
        {"resolution", e.collision.resolution},
        {"overshoot_penalty", e.collision.overshootPenalty}}},
      {"damping", {{"alpha", e.damping.alpha}, {"beta", e.damping.beta}}},
  };
  return j.dump();
}

Result<BuildParameters> parseBuildParameters(const std::string& text) {
  try {
    const json j = json::parse(text);
    BuildParameters p;
    p.entries = j.at("entries").get<std::size_t>();
    for (const json& f : j.at("families")) {
      const auto family = volume::parseFamily(f.get<std::string>());
      if (!family)
        return Error{ErrorCode::kParse,
                     "unknown family '" + f.get<std::string>() + "' in the build parameters"};
      p.families.push_back(*family);
    }
    if (const auto w = j.find("weights"); w != j.end()) {
      p.weights = w->get<std::vector<unsigned>>();
      if (!volume::validFamilyWeights(p.families.size(), p.weights))
        return Error{ErrorCode::kParse, "the build parameters' family weights do not fit their families"};
    }
    p.resolution.segments = j.at("resolution").at("segments").get<int>();
    p.resolution.stacks = j.at("resolution").at("stacks").get<int>();
    // Files from before the stones' subdivisions were stored made them from 320 triangles.
    p.resolution.stoneSubdivisions = j.at("resolution").value("stone_subdivisions", 2);
    if (!volume::validStoneSubdivisions(p.resolution.stoneSubdivisions))
      return Error{ErrorCode::kParse, "the build parameters' stone subdivisions must be " +
                                          std::to_string(volume::kMinStoneSubdivisions) + " to " +
                                          std::to_string(volume::kMaxStoneSubdivisions)};
    // Files from before the unions' own triangle count made them from 20 triangles a segment.
    p.resolution.unionTrianglesPerSegment = j.at("resolution").value("union_triangles_per_segment", 20);
    if (p.resolution.unionTrianglesPerSegment < 1)
      return Error{ErrorCode::kParse, "the build parameters' union triangles per segment must be ≥ 1"};
    volume::EntryOptions& e = p.entry;
    e.descriptor.gridSize = j.at("descriptor").at("grid").get<int>();
    if (e.descriptor.gridSize < 2 || e.descriptor.gridSize > core::kMaxGridSize)
      return Error{ErrorCode::kParse, "the build parameters' descriptor grid must be 2 to " +
                                          std::to_string(core::kMaxGridSize) + " cells across, not " +
                                          std::to_string(e.descriptor.gridSize)};
    const auto sampling = core::parseSampling(j.at("descriptor").at("sampling").get<std::string>());
    if (!sampling) return Error{ErrorCode::kParse, "unknown sampling in the build parameters"};
    e.descriptor.sampling = *sampling;
    e.descriptor.minCellArea = j.at("descriptor").at("min_cell_area").get<double>();
    e.tetgen.maxRadiusEdgeRatio = j.at("tetgen").at("max_radius_edge_ratio").get<double>();
    e.tetgen.maxVolumeFraction = j.at("tetgen").at("max_volume_fraction").get<double>();
    // Files from before the wall bound have none.
    e.tetgen.wallEdgeFraction = j.at("tetgen").value("wall_edge_fraction", 0.0);
    if (!(e.tetgen.wallEdgeFraction >= 0.0 && std::isfinite(e.tetgen.wallEdgeFraction)))
      return Error{ErrorCode::kParse, "the build parameters' wall edge fraction must be finite and ≥ 0"};
    // Files from before the families' own volume bounds mesh every family at the entries'.
    p.volumeFractions.clear();
    if (const auto own = j.at("tetgen").find("family_volume_fractions"); own != j.at("tetgen").end())
      for (const auto& [name, fraction] : own->items()) {
        const auto family = volume::parseFamily(name);
        if (!family)
          return Error{ErrorCode::kParse,
                       "unknown family '" + name + "' in the build parameters' volume bounds"};
        if (!validVolumeFraction(fraction.get<double>()))
          return Error{ErrorCode::kParse,
                       "the build parameters' volume bound of the " + name + " family must be in (0, 1]"};
        p.volumeFractions[*family] = fraction.get<double>();
      }
    e.modal.modes = j.at("modes").at("count").get<int>();
    e.modal.material.poissonRatio = j.at("modes").at("poisson_ratio").get<double>();
    // Files from before quadratic tets have no "elements": theirs are linear.
    const auto order = volume::parseElementOrder(j.at("modes").value("elements", std::string("linear")));
    if (!order) return Error{ErrorCode::kParse, "unknown element order in the build parameters"};
    e.modal.order = *order;
    e.collision.maxShapes = j.at("collision").at("max_shapes").get<int>();
    e.collision.targetCoverage = j.at("collision").at("target_coverage").get<double>();
    e.collision.resolution = j.at("collision").at("resolution").get<int>();
    e.collision.overshootPenalty = j.at("collision").at("overshoot_penalty").get<double>();
    e.damping.alpha = j.at("damping").at("alpha").get<double>();
    e.damping.beta = j.at("damping").at("beta").get<double>();
    return p;
  } catch (const json::exception& e) {
    return Error{ErrorCode::kParse, std::string("unreadable build parameters: ") + e.what()};
  }
}

struct Store::Impl {
  std::filesystem::path path;
  sqlite3* db = nullptr;
  BuildParameters parameters;
  ~Impl() { sqlite3_close_v2(db); }

  /// SQLite's word for the last failure, with the operating system's where it kept one, and what a
  /// failed write most likely means.
  std::string failure(const char* sqliteMessage) const {
    std::string text = sqliteMessage;
    if (const int os = sqlite3_system_errno(db); os != 0) text += " (" + std::string(std::strerror(os)) + ")";
    const int code = sqlite3_extended_errcode(db);
    if (code == SQLITE_IOERR_WRITE || (code & 0xff) == SQLITE_FULL)
      text += "; is the disk full? What was committed before is kept (a build continues with --resume)";
    return text;
  }
  Error sqlError(const std::string& what) const {
    return Error{ErrorCode::kIo, path.string() + ": " + what + ": " + failure(sqlite3_errmsg(db))};
  }
  Status exec(const char* sql) {
    char* message = nullptr;
    if (sqlite3_exec(db, sql, nullptr, nullptr, &message) != SQLITE_OK) {
      const std::string text = failure(message ? message : "unknown error");
      sqlite3_free(message);
      return Error{ErrorCode::kIo, path.string() + ": " + text};
    }
    return Ok{};
  }
  /// Abandons the open transaction; its own failure changes nothing (SQLite rolls back on close anyway).
  void rollback() { sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr); }
  std::optional<std::int64_t> pragma(const char* sql) {
    Statement s(db, sql);
    if (!s.ok() || s.step() != SQLITE_ROW) return std::nullopt;
    return s.integer(0);
  }

  static Result<std::unique_ptr<Impl>> connect(const std::filesystem::path& path, int flags) {
    auto impl = std::make_unique<Impl>();
    impl->path = path;
    if (sqlite3_open_v2(path.c_str(), &impl->db, flags | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK)
      return impl->sqlError("cannot open the database");
    sqlite3_busy_timeout(impl->db, 10000);
    sqlite3_extended_result_codes(impl->db, 1);
    // A database file is passed around, so it is untrusted input: SQLite's defences for such files
    // (no writes to the schema or the file outside SQL's own, no functions with side effects called
    // from the schema, bounded strings, blobs and statements, nothing attached).
    sqlite3_db_config(impl->db, SQLITE_DBCONFIG_DEFENSIVE, 1, nullptr);
    sqlite3_db_config(impl->db, SQLITE_DBCONFIG_TRUSTED_SCHEMA, 0, nullptr);
    sqlite3_limit(impl->db, SQLITE_LIMIT_LENGTH, kMaxValueBytes);
    sqlite3_limit(impl->db, SQLITE_LIMIT_SQL_LENGTH, 100'000);
    sqlite3_limit(impl->db, SQLITE_LIMIT_ATTACHED, 0);
    return impl;
  }
};

Store::Store(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;
Store::~Store() = default;

const std::filesystem::path& Store::path() const {
  return mImpl->path;
}
const BuildParameters& Store::parameters() const {
  return mImpl->parameters;
}

Result<Store> Store::create(const std::filesystem::path& path, const BuildParameters& parameters) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec))
    return Error{ErrorCode::kIo, path.string() + ": already exists (resume its build, or remove it first)"};
  auto impl = Impl::connect(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  if (!impl) return impl.error();
  Impl& s = **impl;
  const std::string header =
      "PRAGMA journal_mode=WAL; PRAGMA application_id=" + std::to_string(kApplicationId) +
      "; PRAGMA user_version=" + std::to_string(kSchemaVersion) + ";";
  if (Status st = s.exec(header.c_str()); !st) return st.error();
  if (Status st = s.exec("BEGIN"); !st) return st.error();
  if (Status st = s.exec(kSchema); !st) return st.error();
  s.parameters = parameters;
  Store store(std::move(impl).value());
  if (Status st = store.setMeta("parameters", toJson(parameters)); !st) return st.error();
  if (Status st = store.mImpl->exec("COMMIT"); !st) return st.error();
  return store;
}

Result<Store> Store::open(const std::filesystem::path& path, bool writable) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return Error{ErrorCode::kIo, path.string() + (std::filesystem::is_directory(path, ec)
                                                      ? ": is a directory, not a database file"
                                                      : ": no such database file")};
  auto impl = Impl::connect(path, writable ? SQLITE_OPEN_READWRITE : SQLITE_OPEN_READONLY);
  if (!impl) return impl.error();
  Impl& s = **impl;
  if (writable && sqlite3_db_readonly(s.db, "main") == 1)
    return Error{ErrorCode::kIo, path.string() + ": the file is read-only (no write permission)"};
  const auto application = s.pragma("PRAGMA application_id");
  if (!application) {
    if ((sqlite3_extended_errcode(s.db) & 0xff) == SQLITE_NOTADB)
      return Error{ErrorCode::kParse, path.string() + ": not a database file"};
    // A file left in write-ahead-log mode (a build or add that did not finish) needs its folder
    // writable even to be read: SQLite keeps the log's index in a file beside it.
    return Error{ErrorCode::kIo, path.string() + ": cannot read it (" + sqlite3_errmsg(s.db) +
                                     "); a file whose build or add did not finish needs a writable folder"};
  }
  if (*application != kApplicationId)
    return Error{ErrorCode::kParse, path.string() + ": not a shapedb database"};
  const auto version = s.pragma("PRAGMA user_version");
  if (version != kSchemaVersion)
    return Error{ErrorCode::kParse, path.string() + ": schema version " +
                                        std::to_string(version.value_or(-1)) +
                                        ", this shapedb reads version " + std::to_string(kSchemaVersion)};
  {
    Statement schema(s.db, "SELECT type, name FROM sqlite_schema ORDER BY rowid");
    if (!schema.ok()) return s.sqlError("reading the schema");
    int rc = 0;
    while ((rc = schema.step()) == SQLITE_ROW)
      if (!isOurSchemaObject(schema.text(0), schema.text(1)))
        return Error{ErrorCode::kParse,
                     path.string() + ": holds " + schema.text(0) + " '" + schema.text(1) +
                         "', which shapedb does not create; an untrusted file is not read (rebuild it, or "
                         "drop that object with sqlite3 if you know where it came from)"};
    if (rc != SQLITE_DONE) return s.sqlError("reading the schema");
  }
  if (writable)
    if (Status st = s.exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;"); !st) return st.error();
  Store store(std::move(impl).value());
  const auto text = store.meta("parameters");
  if (!text) return Error{ErrorCode::kParse, path.string() + ": the build parameters are missing"};
  auto parameters = parseBuildParameters(*text);
  if (!parameters) return withContext(parameters.error(), path.string());
  store.mImpl->parameters = std::move(parameters).value();
  return store;
}

Status Store::finish() {
  return mImpl->exec("PRAGMA journal_mode=DELETE");
}

Status Store::setMeta(const std::string& key, const std::string& value) {
  Statement s(
      mImpl->db,
      "INSERT INTO meta(key, value) VALUES(?, ?) ON CONFLICT(key) DO UPDATE SET value = excluded.value");
  if (!s.ok()) return mImpl->sqlError("writing meta");
  s.bind(1, key);
  s.bind(2, value);
  if (s.step() != SQLITE_DONE) return mImpl->sqlError("writing meta");
  return Ok{};
}

std::optional<std::string> Store::meta(const std::string& key) const {
  Statement s(mImpl->db, "SELECT value FROM meta WHERE key = ?");
  if (!s.ok()) return std::nullopt;
  s.bind(1, key);
  if (s.step() != SQLITE_ROW) return std::nullopt;
  return s.text(0);
}

EncodedEntry encodeEntry(const volume::EntryData& data) {
  EncodedEntry e;
  for (std::size_t k = 0; k < data.descriptors.size(); ++k)
    e.descriptors[k] = encodeDescriptor(data.descriptors[k]);
  const core::PhysicalData& p = data.physics;
  e.physics = {encodeTetMesh(p.tetMesh), encodeMassProperties(p.massProperties), encodeModes(p.modes),
               encodeCollision(p.collision), encodeSound(p.sound)};
  return e;
}

Status Store::write(std::span<const EntryRecord> records, std::span<const volume::EntryData> data,
                    std::span<const FailureRecord> failures) {
  std::vector<EncodedEntry> encoded;
  encoded.reserve(data.size());
  for (const volume::EntryData& d : data)
    encoded.push_back(encodeEntry(d));
  return write(records, encoded, failures);
}

Status Store::write(std::span<const EntryRecord> records, std::span<const EncodedEntry> data,
                    std::span<const FailureRecord> failures) {
  Impl& s = *mImpl;
  if (records.size() != data.size()) return Error{ErrorCode::kInvalidArgument, "one record per entry"};
  if (Status st = s.exec("BEGIN IMMEDIATE"); !st) return st.error();
  const auto fail = [&](const std::string& what) -> Status {
    const Error error = s.sqlError(what);
    s.rollback();
    return error;
  };
  Statement entry(
      s.db,
      "INSERT INTO entries(id, name, family, params, source, nodes, tets, times) VALUES(?,?,?,?,?,?,?,?)");
  Statement descriptor(s.db, "INSERT INTO descriptors(entry_id, kind, data, checksum) VALUES(?,?,?,?)");
  Statement physics(s.db, "INSERT INTO physics(entry_id, part, data, checksum) VALUES(?,?,?,?)");
  Statement failure(s.db, "INSERT OR REPLACE INTO failures(name, message) VALUES(?,?)");
  if (!entry.ok() || !descriptor.ok() || !physics.ok() || !failure.ok()) return fail("preparing the write");
  for (std::size_t i = 0; i < records.size(); ++i) {
    const EntryRecord& r = records[i];
    entry.bind(1, static_cast<std::int64_t>(r.id));
    entry.bind(2, r.name);
    entry.bind(3, std::string(volume::toString(r.family)));
    entry.bind(4, json::array({r.params.x(), r.params.y(), r.params.z()}).dump());
    entry.bind(5, r.source);
    entry.bind(6, static_cast<std::int64_t>(r.nodes));
    entry.bind(7, static_cast<std::int64_t>(r.tets));
    entry.bind(8, timesToJson(r.times).dump());
    if (const int rc = entry.step(); rc != SQLITE_DONE) {
      if ((rc & 0xff) != SQLITE_CONSTRAINT) return fail("writing entry '" + r.name + "'");
      s.rollback();
      return Error{ErrorCode::kInvalidArgument,
                   "entry '" + r.name + "' or id " + std::to_string(r.id) + " is already in the database"};
    }
    entry.reset();
    for (std::size_t k = 0; k < data[i].descriptors.size(); ++k) {
      const Bytes& bytes = data[i].descriptors[k];
      descriptor.bind(1, static_cast<std::int64_t>(r.id));
      descriptor.bind(2, static_cast<std::int64_t>(k));
      descriptor.bind(3, bytes);
      descriptor.bind(4, static_cast<std::int64_t>(checksum(bytes)));
      if (descriptor.step() != SQLITE_DONE) return fail("writing a descriptor of '" + r.name + "'");
      descriptor.reset();
    }
    const std::array<Bytes, 5>& parts = data[i].physics;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      physics.bind(1, static_cast<std::int64_t>(r.id));
      physics.bind(2, static_cast<std::int64_t>(k));
      physics.bind(3, parts[k]);
      physics.bind(4, static_cast<std::int64_t>(checksum(parts[k])));
      if (physics.step() != SQLITE_DONE) return fail("writing the physics of '" + r.name + "'");
      physics.reset();
    }
  }
  for (const FailureRecord& f : failures) {
    failure.bind(1, f.name);
    failure.bind(2, f.message);
    if (failure.step() != SQLITE_DONE) return fail("writing a failure");
    failure.reset();
  }
  if (Status st = s.exec("COMMIT"); !st) {
    s.rollback();
    return st.error();
  }
  return Ok{};
}

Result<EncodedEntry> Store::encoded(core::EntryId id) const {
  const Impl& s = *mImpl;
  const std::string where = s.path.string() + ": entry " + std::to_string(id);
  EncodedEntry out;
  const auto read = [&](const char* sql, auto& blobs, const char* what) -> Status {
    Statement rows(s.db, sql);
    if (!rows.ok()) return s.sqlError("reading entry " + std::to_string(id));
    rows.bind(1, static_cast<std::int64_t>(id));
    std::size_t found = 0;
    int rc = 0;
    while ((rc = rows.step()) == SQLITE_ROW) {
      const std::int64_t k = rows.integer(0);
      if (k < 0 || k >= static_cast<std::int64_t>(blobs.size())) continue;
      const auto* blob = static_cast<const std::uint8_t*>(rows.blob(1));
      if (checksum(blob, rows.blobSize(1)) != static_cast<std::uint32_t>(rows.integer(2)))
        return Error{ErrorCode::kParse, where + ": " + what + " " + std::to_string(k) +
                                            " does not match its checksum (the file is damaged)"};
      blobs[static_cast<std::size_t>(k)].assign(blob, blob + rows.blobSize(1));
      ++found;
    }
    if (rc != SQLITE_DONE) return s.sqlError("reading entry " + std::to_string(id));
    if (found != blobs.size())
      return Error{found == 0 ? ErrorCode::kInvalidArgument : ErrorCode::kParse,
                   where + (found == 0 ? ": no such entry" : std::string(": a ") + what + " is missing")};
    return Ok{};
  };
  if (Status st = read("SELECT kind, data, checksum FROM descriptors WHERE entry_id = ?", out.descriptors,
                       "descriptor");
      !st)
    return st.error();
  if (Status st =
          read("SELECT part, data, checksum FROM physics WHERE entry_id = ?", out.physics, "physics part");
      !st)
    return st.error();
  return out;
}

Result<std::vector<EntryRecord>> Store::entries() const {
  Statement s(mImpl->db,
              "SELECT id, name, family, params, source, nodes, tets, times FROM entries ORDER BY id");
  if (!s.ok()) return mImpl->sqlError("reading entries");
  std::vector<EntryRecord> records;
  int rc = 0;
  while ((rc = s.step()) == SQLITE_ROW) {
    EntryRecord r;
    r.id = static_cast<core::EntryId>(s.integer(0));
    r.name = s.text(1);
    const auto family = volume::parseFamily(s.text(2));
    if (!family)
      return Error{ErrorCode::kParse,
                   mImpl->path.string() + ": entry '" + r.name + "' has an unknown family"};
    r.family = *family;
    try {
      const json params = json::parse(s.text(3));
      r.params =
          core::Vec3(params.at(0).get<double>(), params.at(1).get<double>(), params.at(2).get<double>());
      r.times = timesFromJson(json::parse(s.text(7)));
    } catch (const json::exception&) {
      return Error{ErrorCode::kParse,
                   mImpl->path.string() + ": entry '" + r.name + "' has unreadable parameters"};
    }
    r.source = s.text(4);
    r.nodes = static_cast<std::size_t>(s.integer(5));
    r.tets = static_cast<std::size_t>(s.integer(6));
    records.push_back(std::move(r));
  }
  if (rc != SQLITE_DONE) return mImpl->sqlError("reading entries");
  return records;
}

Result<std::vector<FailureRecord>> Store::failures() const {
  Statement s(mImpl->db, "SELECT name, message FROM failures ORDER BY name");
  if (!s.ok()) return mImpl->sqlError("reading failures");
  std::vector<FailureRecord> failures;
  int rc = 0;
  while ((rc = s.step()) == SQLITE_ROW)
    failures.push_back({s.text(0), s.text(1)});
  if (rc != SQLITE_DONE) return mImpl->sqlError("reading failures");
  return failures;
}

Status Store::forEachDescriptor(
    core::DescriptorKind kind,
    const std::function<Status(core::EntryId, const core::Descriptor&)>& visit) const {
  Statement s(mImpl->db, "SELECT entry_id, data, checksum FROM descriptors WHERE kind = ? ORDER BY entry_id");
  if (!s.ok()) return mImpl->sqlError("reading descriptors");
  s.bind(1, static_cast<std::int64_t>(kind));
  int rc = 0;
  while ((rc = s.step()) == SQLITE_ROW) {
    const auto id = static_cast<core::EntryId>(s.integer(0));
    const std::string where = mImpl->path.string() + ": entry " + std::to_string(id);
    if (checksum(s.blob(1), s.blobSize(1)) != static_cast<std::uint32_t>(s.integer(2)))
      return Error{ErrorCode::kParse, where + ": descriptor checksum mismatch (the file is corrupted)"};
    auto d = decodeDescriptor(s.blob(1), s.blobSize(1));
    if (!d) return withContext(d.error(), where);
    if (Status st = visit(id, *d); !st) return st;
  }
  if (rc != SQLITE_DONE) return mImpl->sqlError("reading descriptors");
  return Ok{};
}

Result<IntegrityReport> Store::check() const {
  IntegrityReport report;
  {
    Statement s(mImpl->db, "PRAGMA integrity_check");
    if (!s.ok()) return mImpl->sqlError("checking integrity");
    int rc = 0;
    while ((rc = s.step()) == SQLITE_ROW)
      if (const std::string line = s.text(0); line != "ok") report.sqliteProblems.push_back(line);
    if (rc != SQLITE_DONE)
      report.sqliteProblems.push_back(std::string("the check stopped: ") + sqlite3_errmsg(mImpl->db));
  }
  // Every blob against its checksum, named by its entry (a blob of no entry by its id).
  const auto check = [&](const char* sql, const auto& partName) -> Status {
    Statement s(mImpl->db, sql);
    if (!s.ok()) return mImpl->sqlError("checking blobs");
    int rc = 0;
    while ((rc = s.step()) == SQLITE_ROW) {
      ++report.blobsChecked;
      if (checksum(s.blob(2), s.blobSize(2)) == static_cast<std::uint32_t>(s.integer(3))) continue;
      const std::string entry = s.text(4).empty() ? "entry " + std::to_string(s.integer(0)) : s.text(4);
      report.damaged.push_back({static_cast<core::EntryId>(s.integer(0)), entry, partName(s.integer(1))});
    }
    if (rc != SQLITE_DONE) return mImpl->sqlError("checking blobs");
    return Ok{};
  };
  const auto descriptorName = [](std::int64_t kind) {
    return std::string(core::toString(static_cast<core::DescriptorKind>(kind))) + " descriptor";
  };
  const auto partName = [](std::int64_t part) {
    return part >= 0 && part < static_cast<std::int64_t>(kPartNames.size())
               ? std::string(kPartNames[static_cast<std::size_t>(part)])
               : "part " + std::to_string(part);
  };
  if (Status st =
          check("SELECT d.entry_id, d.kind, d.data, d.checksum, coalesce(e.name, '') FROM descriptors d "
                "LEFT JOIN entries e ON e.id = d.entry_id ORDER BY d.entry_id, d.kind",
                descriptorName);
      !st)
    return st.error();
  if (Status st = check("SELECT p.entry_id, p.part, p.data, p.checksum, coalesce(e.name, '') FROM physics p "
                        "LEFT JOIN entries e ON e.id = p.entry_id ORDER BY p.entry_id, p.part",
                        partName);
      !st)
    return st.error();
  return report;
}

Result<core::PhysicalData> Store::physics(core::EntryId id) const {
  Statement s(mImpl->db, "SELECT part, data, checksum FROM physics WHERE entry_id = ? ORDER BY part");
  if (!s.ok()) return mImpl->sqlError("reading physics");
  s.bind(1, static_cast<std::int64_t>(id));
  core::PhysicalData p;
  int found = 0, rc = 0;
  const std::string where = mImpl->path.string() + ": entry " + std::to_string(id);
  while ((rc = s.step()) == SQLITE_ROW) {
    const auto part = s.integer(0);
    if (part < 0 || part >= static_cast<std::int64_t>(kPartNames.size())) continue;
    const std::string what = where + ": " + kPartNames[static_cast<std::size_t>(part)];
    const void* blob = s.blob(1);
    const std::size_t size = s.blobSize(1);
    if (checksum(blob, size) != static_cast<std::uint32_t>(s.integer(2)))
      return Error{ErrorCode::kParse, what + ": checksum mismatch (the file is corrupted)"};
    Status decoded = Ok{};
    const auto take = [&](auto result, auto& into) {
      if (!result)
        decoded = withContext(result.error(), what);
      else
        into = std::move(result).value();
    };
    switch (static_cast<Part>(part)) {
      case Part::kTetMesh:
        take(decodeTetMesh(blob, size), p.tetMesh);
        break;
      case Part::kMassProperties:
        take(decodeMassProperties(blob, size), p.massProperties);
        break;
      case Part::kModes:
        take(decodeModes(blob, size), p.modes);
        break;
      case Part::kCollision:
        take(decodeCollision(blob, size), p.collision);
        break;
      case Part::kSound:
        take(decodeSound(blob, size), p.sound);
        break;
    }
    if (!decoded) return decoded.error();
    ++found;
  }
  if (rc != SQLITE_DONE) return mImpl->sqlError("reading physics");
  if (found == 0) return Error{ErrorCode::kInvalidArgument, where + ": no such entry"};
  if (found != static_cast<int>(kPartNames.size()))
    return Error{ErrorCode::kParse, where + ": physical data incomplete"};
  if (p.modes.shapes.rows() != static_cast<Eigen::Index>(3 * p.tetMesh.nodeCount()))
    return Error{ErrorCode::kParse, where + ": modes do not match the tet mesh"};
  return p;
}

Result<Eigen::VectorXd> Store::eigenvalues(core::EntryId id) const {
  Statement s(mImpl->db, "SELECT data, checksum FROM physics WHERE entry_id = ? AND part = ?");
  if (!s.ok()) return mImpl->sqlError("reading modes");
  s.bind(1, static_cast<std::int64_t>(id));
  s.bind(2, static_cast<std::int64_t>(Part::kModes));
  const std::string what = mImpl->path.string() + ": entry " + std::to_string(id) + ": " +
                           kPartNames[static_cast<std::size_t>(Part::kModes)];
  const int rc = s.step();
  if (rc == SQLITE_DONE) {
    Statement e(mImpl->db, "SELECT 1 FROM entries WHERE id = ?");
    if (!e.ok()) return mImpl->sqlError("reading entries");
    e.bind(1, static_cast<std::int64_t>(id));
    if (e.step() == SQLITE_ROW) return Error{ErrorCode::kParse, what + ": missing"};
    return Error{ErrorCode::kInvalidArgument,
                 mImpl->path.string() + ": entry " + std::to_string(id) + ": no such entry"};
  }
  if (rc != SQLITE_ROW) return mImpl->sqlError("reading modes");
  const void* blob = s.blob(0);
  const std::size_t size = s.blobSize(0);
  if (checksum(blob, size) != static_cast<std::uint32_t>(s.integer(1)))
    return Error{ErrorCode::kParse, what + ": checksum mismatch (the file is corrupted)"};
  auto eigenvalues = decodeEigenvalues(blob, size);
  if (!eigenvalues) return withContext(eigenvalues.error(), what);
  return eigenvalues;
}

}  // namespace shapedb::io
