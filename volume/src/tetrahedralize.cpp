#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <string>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <tetgen.h>

#include <shapedb/core/mass_properties.h>
#include <shapedb/core/topology.h>
#include <shapedb/volume/tetrahedralize.h>

namespace shapedb::volume {
namespace {

using core::TetMesh;
using core::TriangleMesh;

/// TetGen's output, or why there is none: the plain-data form that crosses the pipe from the child.
struct RawResult {
  std::int32_t status = 0;  ///< 0 ok; otherwise TetGen's error code (its terminatetetgen argument)
  std::vector<double> nodes;
  std::vector<std::int32_t> tets;
};

/// Runs TetGen in this process. TetGen reports errors by throwing an int (TETLIBRARY builds).
RawResult runTetGen(const TriangleMesh& surface, const std::string& switches) {
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(surface.vertices.size());
  in.pointlist = new REAL[3 * surface.vertices.size()];
  for (std::size_t i = 0; i < surface.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k)
      in.pointlist[3 * i + static_cast<std::size_t>(k)] = surface.vertices[i][k];
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

  RawResult result;
  std::vector<char> writable(switches.begin(), switches.end());
  writable.push_back('\0');
  try {
    tetrahedralize(writable.data(), &in, &out);
  } catch (int code) {
    result.status = code == 0 ? -1 : code;
    return result;
  }
  if (out.numberoftetrahedra <= 0 || out.numberofcorners != 4) {
    result.status = -1;
    return result;
  }
  result.nodes.assign(out.pointlist, out.pointlist + 3 * out.numberofpoints);
  result.tets.assign(out.tetrahedronlist, out.tetrahedronlist + 4 * out.numberoftetrahedra);
  return result;
}

bool writeAll(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

/// Runs TetGen in a forked child that writes its RawResult into a pipe: status, node count, tet count,
/// then the arrays. A crash in the child is a signal the parent reports, not a crash of the parent.
Result<RawResult> runTetGenGuarded(const TriangleMesh& surface, const std::string& switches, double timeout) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    return Error{ErrorCode::kIo, std::string("pipe: ") + std::strerror(errno)};
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return Error{ErrorCode::kIo, std::string("fork: ") + std::strerror(errno)};
  }
  if (pid == 0) {
    ::close(fds[0]);
    // TetGen prints nothing with 'Q'; anything it or a crash report writes goes to /dev/null. The file
    // descriptors are redirected, not the FILE streams: closing or flushing the inherited stdout would
    // write the parent's pending output a second time.
    const int devnull = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (devnull >= 0) {
      ::dup2(devnull, STDOUT_FILENO);
      ::dup2(devnull, STDERR_FILENO);
    }
    const RawResult raw = runTetGen(surface, switches);
    const std::int64_t header[3] = {raw.status, static_cast<std::int64_t>(raw.nodes.size()),
                                    static_cast<std::int64_t>(raw.tets.size())};
    const bool ok = writeAll(fds[1], header, sizeof header) &&
                    writeAll(fds[1], raw.nodes.data(), raw.nodes.size() * sizeof(double)) &&
                    writeAll(fds[1], raw.tets.data(), raw.tets.size() * sizeof(std::int32_t));
    ::_exit(ok ? 0 : 1);  // no destructors, no atexit handlers of the parent's libraries
  }
  ::close(fds[1]);

  std::vector<char> bytes;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
  bool timedOut = false;
  char buffer[1 << 16];
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timedOut = true;
      break;
    }
    pollfd pfd{fds[0], POLLIN, 0};
    const int ready = ::poll(&pfd, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;  // the deadline check above ends the wait
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.insert(bytes.end(), buffer, buffer + n);
  }
  ::close(fds[0]);
  if (timedOut) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timedOut)
    return Error{ErrorCode::kIo,
                 "TetGen did not finish within " + std::to_string(static_cast<int>(timeout)) + " s"};
  if (WIFSIGNALED(status))
    return Error{ErrorCode::kIo, std::string("TetGen crashed (") + ::strsignal(WTERMSIG(status)) + ")"};
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return Error{ErrorCode::kIo, "TetGen's process failed"};

  std::int64_t header[3];
  if (bytes.size() < sizeof header) return Error{ErrorCode::kIo, "TetGen's process returned no result"};
  std::memcpy(header, bytes.data(), sizeof header);
  RawResult raw;
  raw.status = static_cast<std::int32_t>(header[0]);
  const auto nodeValues = static_cast<std::size_t>(header[1]);
  const auto tetValues = static_cast<std::size_t>(header[2]);
  if (bytes.size() != sizeof header + nodeValues * sizeof(double) + tetValues * sizeof(std::int32_t))
    return Error{ErrorCode::kIo, "TetGen's process returned a truncated result"};
  raw.nodes.resize(nodeValues);
  raw.tets.resize(tetValues);
  std::memcpy(raw.nodes.data(), bytes.data() + sizeof header, nodeValues * sizeof(double));
  std::memcpy(raw.tets.data(), bytes.data() + sizeof header + nodeValues * sizeof(double),
              tetValues * sizeof(std::int32_t));
  return raw;
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

}  // namespace

std::string tetgenSwitches(const TetrahedralizeOptions& options, double volume) {
  // p: the input is a piecewise linear complex; q: quality bound; a: volume bound; Q: quiet;
  // z: number from zero.
  char buffer[96];
  if (options.maxVolumeFraction > 0.0)
    std::snprintf(buffer, sizeof buffer, "pq%.3ga%.6gQz", options.maxRadiusEdgeRatio,
                  options.maxVolumeFraction * volume);
  else
    std::snprintf(buffer, sizeof buffer, "pq%.3gQz", options.maxRadiusEdgeRatio);
  return buffer;
}

Result<TetMesh> tetrahedralize(const TriangleMesh& surface, const TetrahedralizeOptions& options) {
  if (!(options.maxRadiusEdgeRatio >= 1.1 && std::isfinite(options.maxRadiusEdgeRatio)))
    return Error{ErrorCode::kInvalidArgument, "TetGen radius-edge ratio must be at least 1.1"};
  if (!(options.maxVolumeFraction >= 0.0 && options.maxVolumeFraction <= 1.0))
    return Error{ErrorCode::kInvalidArgument, "TetGen volume fraction must be in [0, 1]"};
  if (Status valid = core::validateMesh(surface); !valid) return valid.error();
  auto mass = core::computeMassProperties(surface);
  if (!mass) return mass.error();

  const std::string switches = tetgenSwitches(options, mass->volume);
  RawResult raw;
  if (options.guarded) {
    auto guarded = runTetGenGuarded(surface, switches, options.timeoutSeconds);
    if (!guarded) return guarded.error();
    raw = std::move(guarded).value();
  } else {
    raw = runTetGen(surface, switches);
  }
  if (raw.status != 0) return Error{ErrorCode::kParse, describeTetGenError(raw.status)};

  TetMesh mesh;
  mesh.nodes.resize(raw.nodes.size() / 3);
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    mesh.nodes[i] = core::Vec3(raw.nodes[3 * i], raw.nodes[3 * i + 1], raw.nodes[3 * i + 2]);
  mesh.tets.resize(raw.tets.size() / 4);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (std::size_t k = 0; k < 4; ++k) {
      const std::int32_t v = raw.tets[4 * t + k];
      if (v < 0 || static_cast<std::size_t>(v) >= mesh.nodes.size())
        return Error{ErrorCode::kParse, "TetGen returned a tet with an invalid node"};
      mesh.tets[t][k] = static_cast<std::uint32_t>(v);
    }
    // TetGen orients tets negatively in our convention (its manual's right-hand rule); make them positive.
    if (core::tetVolume(mesh, t) < 0.0) std::swap(mesh.tets[t][2], mesh.tets[t][3]);
  }
  if (Status valid = core::validateTetMesh(mesh); !valid)
    return Error{ErrorCode::kParse, "TetGen returned an invalid mesh: " + valid.error().message};
  return mesh;
}

}  // namespace shapedb::volume
