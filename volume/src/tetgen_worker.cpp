#include "tetgen_worker.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <tetgen.h>

#include <shapedb/core/socket_io.h>
#include <shapedb/core/spatial.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume {
namespace detail {

using core::TriangleMesh;

namespace {

/// What the tetunsuitable hook reads: TetGen's hook takes no argument of ours, so the run in progress on
/// this thread leaves it here.
struct LocalVolumeBound {
  const core::ClosestPointTree* tree = nullptr;
  const std::vector<double>* maxVolumes = nullptr;
};
thread_local LocalVolumeBound tLocalBound;

/// TetGen's tetunsuitable hook: whether the tet abcd is larger than the bound of the surface triangle
/// closest to its centroid.
bool overLocalVolumeBound(REAL* a, REAL* b, REAL* c, REAL* d, REAL* /*elen*/, REAL /*area*/) {
  const core::Vec3 pa(a[0], a[1], a[2]), pb(b[0], b[1], b[2]), pc(c[0], c[1], c[2]), pd(d[0], d[1], d[2]);
  const double maxVolume =
      (*tLocalBound.maxVolumes)[tLocalBound.tree->closest((pa + pb + pc + pd) / 4.0).triangle];
  return std::abs((pb - pa).cross(pc - pa).dot(pd - pa)) / 6.0 > maxVolume;
}

}  // namespace

TetGenOutput runTetGen(const TriangleMesh& surface, const std::vector<double>& maxVolumes,
                       const std::vector<core::Vec3>& holes, const std::string& switches) {
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(surface.vertices.size());
  in.pointlist = new REAL[3 * surface.vertices.size()];
  for (std::size_t i = 0; i < surface.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k)
      in.pointlist[3 * i + static_cast<std::size_t>(k)] = surface.vertices[i][k];
  core::ClosestPointTree tree;
  if (!maxVolumes.empty()) {
    // Serial: this runs in TetGen's forked worker too, which has none of the parent's TBB threads.
    tree = core::ClosestPointTree(surface, /*parallel=*/false);
    tLocalBound = {&tree, &maxVolumes};
    in.tetunsuitable = &overLocalVolumeBound;
  }
  if (!holes.empty()) {
    in.numberofholes = static_cast<int>(holes.size());
    in.holelist = new REAL[3 * holes.size()];
    for (std::size_t i = 0; i < holes.size(); ++i)
      for (int k = 0; k < 3; ++k)
        in.holelist[3 * i + static_cast<std::size_t>(k)] = holes[i][k];
  }
  in.numberoffacets = static_cast<int>(surface.triangles.size());
  in.facetlist = new tetgenio::facet[surface.triangles.size()];
  for (std::size_t f = 0; f < surface.triangles.size(); ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k)
      facet.polygonlist[0].vertexlist[k] =
          static_cast<int>(surface.triangles[f][static_cast<std::size_t>(k)]);
  }

  TetGenOutput result;
  std::vector<char> writable(switches.begin(), switches.end());
  writable.push_back('\0');
  try {
    tetrahedralize(writable.data(), &in, &out);
  } catch (int code) {
    result.status = code == 0 ? -1 : code;
  }
  in.tetunsuitable = nullptr;
  tLocalBound = {};
  if (result.status != 0) return result;
  if (out.numberoftetrahedra <= 0 || out.numberofcorners != 4) {
    result.status = -1;
    return result;
  }
  result.nodes.assign(out.pointlist, out.pointlist + 3 * out.numberofpoints);
  result.tets.assign(out.tetrahedronlist, out.tetrahedronlist + 4 * out.numberoftetrahedra);
  return result;
}

namespace {

using core::Deadline;
using core::receiveAll;
using core::sendAll;

// testing::killNextTetGenWorkers: how many requests are still to find their worker killed.
std::atomic<int> gWorkersToKill{0};
// testing::tetGenWorkersStarted: the workers this process has forked.
std::atomic<int> gWorkersStarted{0};

bool takeInjectedKill() {
  int left = gWorkersToKill.load();
  while (left > 0 && !gWorkersToKill.compare_exchange_weak(left, left - 1)) {
  }
  return left > 0;
}

/// The child's side: requests in (switches, vertices, triangles, local volume bounds, hole points),
/// TetGenOutputs out, until the parent closes the socket. Never returns.
[[noreturn]] void serveTetGen(int fd) {
  const Deadline never = std::chrono::steady_clock::time_point::max();
  for (;;) {
    bool timedOut = false;
    // switches length, vertex count, triangle count, local bound count, hole count
    std::uint64_t header[5];
    if (!receiveAll(fd, header, sizeof header, never, timedOut)) ::_exit(0);
    std::string switches(header[0], '\0');
    TriangleMesh surface;
    surface.vertices.resize(header[1]);
    surface.triangles.resize(header[2]);
    std::vector<double> maxVolumes(header[3]);
    std::vector<core::Vec3> holes(header[4]);
    if (!receiveAll(fd, switches.data(), switches.size(), never, timedOut) ||
        !receiveAll(fd, surface.vertices.data(), surface.vertices.size() * sizeof(core::Vec3), never,
                    timedOut) ||
        !receiveAll(fd, surface.triangles.data(), surface.triangles.size() * sizeof(TriangleMesh::Triangle),
                    never, timedOut) ||
        !receiveAll(fd, maxVolumes.data(), maxVolumes.size() * sizeof(double), never, timedOut) ||
        !receiveAll(fd, holes.data(), holes.size() * sizeof(core::Vec3), never, timedOut))
      ::_exit(1);
    const TetGenOutput raw = runTetGen(surface, maxVolumes, holes, switches);
    const std::int64_t reply[3] = {raw.status, static_cast<std::int64_t>(raw.nodes.size()),
                                   static_cast<std::int64_t>(raw.tets.size())};
    if (!sendAll(fd, reply, sizeof reply) ||
        !sendAll(fd, raw.nodes.data(), raw.nodes.size() * sizeof(double)) ||
        !sendAll(fd, raw.tets.data(), raw.tets.size() * sizeof(std::int32_t)))
      ::_exit(1);
  }
}

/// A child process that runs TetGen for one thread of the parent, request after request. Forked once and
/// reused: a fork per call costs more than TetGen itself on small meshes (the parent's pages turn
/// copy-on-write at every fork, and every later write to them faults). A crash or a hang in the child
/// costs that one request: the child is reaped and the next request forks a fresh one.
class TetGenWorker {
 public:
  ~TetGenWorker() { stop(); }

  /// Forks the worker unless it is running.
  Status ensureStarted() { return mPid > 0 ? Status(Ok{}) : start(); }

  Result<TetGenOutput> run(const TriangleMesh& surface, const std::vector<double>& maxVolumes,
                           const std::vector<core::Vec3>& holes, const std::string& switches,
                           double timeout) {
    if (Status st = ensureStarted(); !st) return st.error();
    if (takeInjectedKill()) ::kill(mPid, SIGKILL);
    const Deadline deadline =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(timeout));
    const std::uint64_t header[5] = {switches.size(), surface.vertices.size(), surface.triangles.size(),
                                     maxVolumes.size(), holes.size()};
    bool timedOut = false;
    std::int64_t reply[3] = {0, 0, 0};
    bool ok =
        sendAll(mFd, header, sizeof header) && sendAll(mFd, switches.data(), switches.size()) &&
        sendAll(mFd, surface.vertices.data(), surface.vertices.size() * sizeof(core::Vec3)) &&
        sendAll(mFd, surface.triangles.data(), surface.triangles.size() * sizeof(TriangleMesh::Triangle)) &&
        sendAll(mFd, maxVolumes.data(), maxVolumes.size() * sizeof(double)) &&
        sendAll(mFd, holes.data(), holes.size() * sizeof(core::Vec3)) &&
        receiveAll(mFd, reply, sizeof reply, deadline, timedOut);
    TetGenOutput raw;
    if (ok && reply[1] >= 0 && reply[2] >= 0 && reply[1] < (std::int64_t{1} << 34) &&
        reply[2] < (std::int64_t{1} << 34)) {
      raw.status = static_cast<std::int32_t>(reply[0]);
      raw.nodes.resize(static_cast<std::size_t>(reply[1]));
      raw.tets.resize(static_cast<std::size_t>(reply[2]));
      ok = receiveAll(mFd, raw.nodes.data(), raw.nodes.size() * sizeof(double), deadline, timedOut) &&
           receiveAll(mFd, raw.tets.data(), raw.tets.size() * sizeof(std::int32_t), deadline, timedOut);
    } else {
      ok = false;
    }
    if (ok) return raw;
    // The child died or hung on this input: reap it, say why, and start afresh next time.
    const int status = stop();
    if (timedOut)
      return Error{ErrorCode::kIo,
                   "TetGen did not finish within " + std::to_string(static_cast<int>(timeout)) + " s"};
    if (WIFSIGNALED(status))
      return Error{ErrorCode::kIo, std::string("TetGen crashed (") + ::strsignal(WTERMSIG(status)) + ")"};
    return Error{ErrorCode::kIo, "TetGen's process failed"};
  }

 private:
  Status start() {
    int fds[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
      return Error{ErrorCode::kIo, std::string("socketpair: ") + std::strerror(errno)};
    const pid_t pid = ::fork();
    if (pid < 0) {
      ::close(fds[0]);
      ::close(fds[1]);
      return Error{ErrorCode::kIo, std::string("fork: ") + std::strerror(errno)};
    }
    if (pid == 0) {
      ::close(fds[0]);
      // TetGen prints nothing with 'Q'; anything it or a crash report writes goes to /dev/null.
      serveTetGen(core::isolateWorker(fds[1]));
    }
    ::close(fds[1]);
    mFd = fds[0];
    mPid = pid;
    gWorkersStarted.fetch_add(1);
    return Ok{};
  }

  /// Closes the socket, kills the child (idle, or already failed: nothing to lose) and reaps it; returns
  /// its wait status, which says how it died if it died first.
  int stop() {
    int status = 0;
    if (mFd >= 0) ::close(mFd);
    if (mPid > 0) ::kill(mPid, SIGKILL);
    if (mPid > 0)
      while (::waitpid(mPid, &status, 0) < 0 && errno == EINTR) {
      }
    mFd = -1;
    mPid = -1;
    return status;
  }

  pid_t mPid = -1;
  int mFd = -1;
};

/// This thread's worker.
TetGenWorker& threadWorker() {
  thread_local TetGenWorker worker;
  return worker;
}

}  // namespace

Result<TetGenOutput> runTetGenGuarded(const TriangleMesh& surface, const std::vector<double>& maxVolumes,
                                      const std::vector<core::Vec3>& holes, const std::string& switches,
                                      double timeout) {
  return threadWorker().run(surface, maxVolumes, holes, switches, timeout);
}

/// TetGen's error codes (terminatetetgen in tetgen.cxx).
std::string describeTetGenError(int code) {
  switch (code) {
    case 1:
      return "TetGen ran out of memory";
    case 2:
      return "TetGen hit an internal error";
    case 3:
      return "TetGen found self-intersecting faces in the surface";
    case 4:
      return "TetGen found a very small input feature it cannot resolve";
    case 5:
      return "TetGen found two very close input faces";
    case 10:
      return "TetGen found an input error";
    default:
      return "TetGen failed (code " + std::to_string(code) + ")";
  }
}

}  // namespace detail

Status startTetGenWorker() {
  return detail::threadWorker().ensureStarted();
}

namespace testing {
void killNextTetGenWorkers(int count) {
  detail::gWorkersToKill.store(std::max(count, 0));
}
int tetGenWorkersStarted() {
  return detail::gWorkersStarted.load();
}
}  // namespace testing

}  // namespace shapedb::volume
