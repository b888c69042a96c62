#include "support/subprocess.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <sys/wait.h>
#include <unistd.h>

#include "support/test_support.h"

namespace shapedb::test {

ProcessResult runProcess(const std::string& program, const std::vector<std::string>& args) {
  // Output goes to files in a scratch directory: no pipe can fill up and block the child.
  ScratchDir dir("process");
  const std::string outPath = (dir / "out").string(), errPath = (dir / "err").string();
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  ProcessResult result;
  std::fflush(nullptr);  // or the child's freopen flushes our pending output a second time
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!std::freopen(outPath.c_str(), "w", stdout) || !std::freopen(errPath.c_str(), "w", stderr))
      ::_exit(126);
    ::execv(program.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream out(outPath), err(errPath);
  result.out.assign(std::istreambuf_iterator<char>(out), {});
  result.err.assign(std::istreambuf_iterator<char>(err), {});
  return result;
}

}  // namespace shapedb::test
