#pragma once

// Shared by the fuzz targets: shapedb reads meshes and databases from files, so each input is written
// to a scratch file of this process first (tmpfs when there is one), then read back the way users do.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace shapedb::fuzz {

/// A file name of this process's own, with `extension` (".obj"): fixed for the process, so that every
/// input overwrites the last one; unique per process, so that parallel fuzzing jobs do not collide.
inline std::filesystem::path scratchPath(const std::string& extension) {
  const std::filesystem::path shm = "/dev/shm";
  std::error_code ec;
  const std::filesystem::path dir =
      std::filesystem::is_directory(shm, ec) ? shm : std::filesystem::temp_directory_path();
  return dir / ("shapedb-fuzz-" + std::to_string(::getpid()) + extension);
}

/// Writes the input to `path`, replacing what was there. Aborts if it cannot: a fuzzer that silently
/// read nothing would be no fuzzer.
inline void writeInput(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr || (size > 0 && std::fwrite(data, 1, size, file) != size) || std::fclose(file) != 0) {
    std::perror(path.c_str());
    std::abort();
  }
}

/// Fails loudly (abort: the fuzzer keeps the input) when a property of the code under test is broken.
#define SHAPEDB_FUZZ_CHECK(condition)                                                         \
  do {                                                                                        \
    if (!(condition)) {                                                                       \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                           \
    }                                                                                         \
  } while (false)

}  // namespace shapedb::fuzz
