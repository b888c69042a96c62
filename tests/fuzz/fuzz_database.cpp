// Fuzz target: a database file as users open it (io::Database::open: SQLite header, application id,
// schema version, build parameters, every descriptor into the indexes), then each entry's physical
// data read through the cache, as a query would. The input is the whole file; the seed is a real
// small database, so mutations reach the pages that hold blobs and parameters. Checked beyond "no
// crash, no leak, no UB": every error names the file.

#include <shapedb/io/database.h>

#include "fuzz_support.h"

namespace shapedb::fuzz {
namespace {

void removeSidecars(const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::remove(path.string() + "-wal", ec);
  std::filesystem::remove(path.string() + "-shm", ec);
}

void openAndRead(const std::filesystem::path& path) {
  io::Database::OpenOptions options;
  options.cacheEntries = 2;
  Result<io::Database> database = io::Database::open(path, options);
  if (!database) {
    SHAPEDB_FUZZ_CHECK(database.error().message.rfind(path.string() + ": ", 0) == 0);
    return;
  }
  std::size_t read = 0;
  for (const io::EntryRecord& entry : database->entries()) {
    if (++read > 16) break;  // bounded work per input
    Result<std::shared_ptr<const core::PhysicalData>> physics = database->physics(entry.id);
    if (!physics) SHAPEDB_FUZZ_CHECK(physics.error().message.find(path.string()) != std::string::npos);
  }
}

}  // namespace
}  // namespace shapedb::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path path = shapedb::fuzz::scratchPath(".db");
  shapedb::fuzz::removeSidecars(path);
  shapedb::fuzz::writeInput(path, data, size);
  shapedb::fuzz::openAndRead(path);
  shapedb::fuzz::removeSidecars(path);
  return 0;
}
