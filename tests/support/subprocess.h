#pragma once

// Runs a real executable as a child process and captures what it prints, for end-to-end tests.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace shapedb::test {

struct ProcessResult {
  int exitCode = -1;           ///< the child's exit status, or 128 + signal if it was killed
  std::string out;             ///< everything written to stdout
  std::string err;             ///< everything written to stderr
  bool timedOut = false;       ///< killed (SIGKILL) for running past RunOptions::timeoutSeconds
  std::int64_t maxRssKiB = 0;  ///< the child's peak resident set, KiB (getrusage)
};

/// Limits put on the child.
struct RunOptions {
  double timeoutSeconds = 0.0;      ///< > 0: SIGKILL the child after this long
  std::uint64_t fileSizeLimit = 0;  ///< > 0: RLIMIT_FSIZE, writes past it fail with EFBIG (a full disk)
  /// Run as root, the child drops CAP_DAC_OVERRIDE and CAP_DAC_READ_SEARCH (from its bounding and
  /// inheritable sets, so they stay dropped across exec): file permissions then apply to it as to any
  /// user, and a file without write permission is read-only for it. No effect for other users.
  bool obeyFilePermissions = false;
};

/// Exit status of a child that could not set up RunOptions (rlimit or capabilities).
inline constexpr int kSetupFailedExit = 125;

/// Runs `program` with `args` (no shell), waits for it, and returns its exit code and output.
ProcessResult runProcess(const std::string& program, const std::vector<std::string>& args,
                         const RunOptions& options = {});

/// Polls `condition` every 20 ms until it holds (true) or `timeoutSeconds` have passed (false): for a test
/// that waits for a child to reach a point in its work.
bool waitUntil(const std::function<bool()>& condition, double timeoutSeconds);

/// A child started and left running, for tests that kill it in the middle of its work: its output goes
/// to /dev/null. Killed (SIGKILL) and reaped when destroyed, if it still runs.
class RunningProcess {
 public:
  RunningProcess(const std::string& program, const std::vector<std::string>& args);
  RunningProcess(const RunningProcess&) = delete;
  RunningProcess& operator=(const RunningProcess&) = delete;
  ~RunningProcess();
  bool started() const { return mPid > 0; }
  /// SIGKILLs the child and reaps it: true if that signal ended it (false: it had exited before).
  bool kill();

 private:
  int mPid = -1;
};

}  // namespace shapedb::test
