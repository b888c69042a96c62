#include <mutex>

#include <openvdb/openvdb.h>

#include <shapedb/volume/openvdb_runtime.h>

namespace shapedb::volume {

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string openVdbVersion() {
  return std::to_string(openvdb::OPENVDB_LIBRARY_MAJOR_VERSION) + "." +
         std::to_string(openvdb::OPENVDB_LIBRARY_MINOR_VERSION) + "." +
         std::to_string(openvdb::OPENVDB_LIBRARY_PATCH_VERSION);
}

}  // namespace shapedb::volume
