#pragma once
// What the CLI's end-to-end tests share: the shapedb binary (SHAPEDB_CLI, set by tests/CMakeLists.txt)
// run as a subprocess.

#include <filesystem>
#include <string>

#include "support/subprocess.h"

namespace shapedb::test {

/// `shapedb build DB --entries N --families F --modes M --quiet`: a small database built by the real
/// command, for the tests of the commands that read one.
inline ProcessResult buildWithCli(const std::filesystem::path& db, int entries, const std::string& families,
                                  int modes) {
  return runProcess(SHAPEDB_CLI, {"build", db.string(), "--entries", std::to_string(entries), "--families",
                                  families, "--modes", std::to_string(modes), "--quiet"});
}

}  // namespace shapedb::test
