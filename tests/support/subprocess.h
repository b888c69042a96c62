#pragma once

// Runs a real executable as a child process and captures what it prints, for end-to-end tests.

#include <string>
#include <vector>

namespace shapedb::test {

struct ProcessResult {
  int exitCode = -1;  ///< the child's exit status, or 128 + signal if it was killed
  std::string out;    ///< everything written to stdout
  std::string err;    ///< everything written to stderr
};

/// Runs `program` with `args` (no shell), waits for it, and returns its exit code and output.
ProcessResult runProcess(const std::string& program, const std::vector<std::string>& args);

}  // namespace shapedb::test
