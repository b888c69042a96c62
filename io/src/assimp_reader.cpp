#include "assimp_reader.h"

#include <assimp/cimport.h>
#include <assimp/metadata.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <signal.h>
#include <string>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <shapedb/core/socket_io.h>
#include <shapedb/io/mesh_io.h>

#include "mesh_format.h"

namespace shapedb::io::detail {

namespace {

/// What the worker sends first: how its reading went and, if it went well, what follows.
struct ReplyHeader {
  enum Status : std::uint64_t { kRead = 0, kAssimpFailed = 1, kNoLibrary = 2, kTooMany = 3, kNoMesh = 4 };
  std::uint64_t status = kRead;
  std::uint64_t vertices = 0, triangles = 0;  ///< kRead: then 3 doubles a vertex, 3 indices a triangle
  std::uint64_t meshInstances = 0, skipped = 0;
  double unit = 1.0;
  std::uint64_t messageBytes = 0;  ///< otherwise: the message that follows
};

/// The worker's reply: one of the failures, with its message.
[[noreturn]] void replyFailure(int fd, ReplyHeader::Status status, const std::string& message) {
  ReplyHeader h;
  h.status = status;
  h.messageBytes = message.size();
  core::sendAll(fd, &h, sizeof h);
  core::sendAll(fd, message.data(), message.size());
  ::_exit(0);
}

/// A node of the scene with the transform from it to the scene's frame.
struct Placed {
  const aiNode* node;
  core::Mat4 transform;
};

core::Mat4 toMat4(const aiMatrix4x4& m) {
  core::Mat4 out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return out;
}

/// The worker: loads assimp, reads the file, sends its triangles on `fd`. Never returns.
[[noreturn]] void readInWorker(int fd, const char* path, bool fbx) {
  const char* library = std::getenv("SHAPEDB_ASSIMP");
  if (library == nullptr || *library == '\0') library = "libassimp.so.5";
  void* assimp = ::dlopen(library, RTLD_NOW | RTLD_LOCAL);
  if (assimp == nullptr) replyFailure(fd, ReplyHeader::kNoLibrary, ::dlerror());
  const auto importFile = reinterpret_cast<decltype(&aiImportFile)>(::dlsym(assimp, "aiImportFile"));
  const auto errorString = reinterpret_cast<decltype(&aiGetErrorString)>(::dlsym(assimp, "aiGetErrorString"));
  if (importFile == nullptr || errorString == nullptr)
    replyFailure(fd, ReplyHeader::kNoLibrary, std::string(library) + " has no aiImportFile: not assimp");
  const aiScene* scene =
      importFile(path, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr) replyFailure(fd, ReplyHeader::kAssimpFailed, errorString());
  if (scene->mRootNode == nullptr) replyFailure(fd, ReplyHeader::kAssimpFailed, "the file has no scene");
  // A scene without meshes comes back incomplete, with a made-up mesh of its nodes' skeleton in it.
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0)
    replyFailure(fd, ReplyHeader::kNoMesh, "no mesh in the scene");

  ReplyHeader h;
  if (fbx && scene->mMetaData != nullptr) {
    // FBX keeps centimetres per unit; assimp 5.2 leaves the coordinates in the file's unit.
    double factor = 0.0;
    float single = 0.0f;
    if (scene->mMetaData->Get("UnitScaleFactor", factor) ||
        scene->mMetaData->Get("UnitScaleFactor", single)) {
      if (factor == 0.0) factor = single;
      if (std::isfinite(factor) && factor > 0.0) h.unit = factor / 100.0;
    }
  }
  // Every mesh each node places, through the transforms down the hierarchy (a tree: assimp makes it one).
  constexpr std::uint64_t kLimit = std::uint64_t{1} << 31;  // indices are 32-bit
  std::vector<core::Vec3> vertices;
  std::vector<std::uint32_t> triangles;
  std::vector<Placed> stack{{scene->mRootNode, core::Mat4::Identity()}};
  while (!stack.empty()) {
    const Placed here = stack.back();
    stack.pop_back();
    const core::Mat4 t = here.transform * toMat4(here.node->mTransformation);
    for (unsigned c = 0; c < here.node->mNumChildren; ++c)
      stack.push_back({here.node->mChildren[c], t});
    const double det = t.topLeftCorner<3, 3>().determinant();
    for (unsigned k = 0; k < here.node->mNumMeshes; ++k) {
      const unsigned index = here.node->mMeshes[k];
      if (index >= scene->mNumMeshes) continue;
      const aiMesh* mesh = scene->mMeshes[index];
      if ((mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) {
        ++h.skipped;  // points or lines: no surface
        continue;
      }
      const std::uint64_t first = vertices.size();
      if (first + mesh->mNumVertices >= kLimit || triangles.size() / 3 + mesh->mNumFaces >= kLimit)
        replyFailure(fd, ReplyHeader::kTooMany, "more than 2^31 vertices or triangles");
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D& p = mesh->mVertices[v];
        vertices.push_back(h.unit * core::transformPoint(t, core::Vec3(p.x, p.y, p.z)));
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) {
          ++h.skipped;
          continue;
        }
        // A mirroring transform turns the surface inside out: rewind to keep it facing out.
        const std::uint32_t a = face.mIndices[0], b = face.mIndices[det < 0.0 ? 2 : 1],
                            c = face.mIndices[det < 0.0 ? 1 : 2];
        for (const std::uint32_t corner : {a, b, c})
          triangles.push_back(corner < mesh->mNumVertices ? static_cast<std::uint32_t>(first + corner)
                                                          : RawPolygons::kInvalidIndex);
      }
      ++h.meshInstances;
    }
  }
  h.vertices = vertices.size();
  h.triangles = triangles.size() / 3;
  if (core::sendAll(fd, &h, sizeof h) &&
      core::sendAll(fd, vertices.data(), vertices.size() * sizeof(core::Vec3)))
    core::sendAll(fd, triangles.data(), triangles.size() * sizeof(std::uint32_t));
  ::_exit(0);
}

Error fileError(const std::filesystem::path& path, ErrorCode code, const std::string& message) {
  return Error{code, path.string() + ": " + message};
}

}  // namespace

Result<RawPolygons> readWithAssimp(const std::filesystem::path& path,
                                   const std::optional<std::uint64_t>& memoryBudget, AssimpReport* report) {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
    return fileError(path, ErrorCode::kIo, std::string("socketpair: ") + std::strerror(errno));
  const std::string file = path.string();
  const bool fbx = lowercaseExtension(path) == "fbx";
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return fileError(path, ErrorCode::kIo, std::string("fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    readInWorker(core::isolateWorker(fds[1]), file.c_str(), fbx);  // assimp's output to /dev/null
  }
  ::close(fds[1]);
  const int fd = fds[0];
  const core::Deadline deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(kAssimpTimeoutSeconds));
  bool timedOut = false;
  ReplyHeader h;
  RawPolygons raw;
  std::string message;
  std::optional<Error> refused;
  bool received = core::receiveAll(fd, &h, sizeof h, deadline, timedOut);
  if (received && h.status == ReplyHeader::kRead) {
    MeshFileSize size;
    size.vertices = h.vertices;
    size.triangles = h.triangles;
    if (memoryBudget && *memoryBudget > 0 && size.bytes() > *memoryBudget) {
      refused = fileError(path, ErrorCode::kTooLarge,
                          "a mesh of " + std::to_string(h.triangles) + " triangles and " +
                              std::to_string(h.vertices) + " vertices needs about " +
                              std::to_string(size.bytes() >> 20) + " MiB to be loaded and queried, and " +
                              std::to_string(*memoryBudget >> 20) + " MiB is available: not read");
    } else if (h.vertices < (std::uint64_t{1} << 31) && h.triangles < (std::uint64_t{1} << 31)) {
      raw.vertices.resize(h.vertices);
      raw.corners.resize(3 * h.triangles);
      received = core::receiveAll(fd, raw.vertices.data(), raw.vertices.size() * sizeof(core::Vec3), deadline,
                                  timedOut) &&
                 core::receiveAll(fd, raw.corners.data(), raw.corners.size() * sizeof(std::uint32_t),
                                  deadline, timedOut);
      raw.ends.resize(h.triangles);
      for (std::size_t f = 0; f < raw.ends.size(); ++f)
        raw.ends[f] = 3 * (f + 1);
    } else {
      received = false;
    }
  } else if (received && h.messageBytes < (1u << 20)) {
    message.resize(h.messageBytes);
    received = core::receiveAll(fd, message.data(), message.size(), deadline, timedOut);
  }
  ::close(fd);
  if (!received || refused) ::kill(pid, SIGKILL);  // hung, or refused: nothing more to wait for
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (refused) return *refused;
  if (!received) {
    if (timedOut)
      return fileError(path, ErrorCode::kParse,
                       "assimp did not finish reading it within " +
                           std::to_string(static_cast<int>(kAssimpTimeoutSeconds)) + " s");
    if (WIFSIGNALED(status))
      return fileError(path, ErrorCode::kParse,
                       std::string("assimp crashed reading it (") + ::strsignal(WTERMSIG(status)) +
                           "): the file is malformed, or of a kind assimp cannot read");
    // Exited without an answer: a crash that a sanitizer's handler (or assimp's) turned into an exit.
    return fileError(path, ErrorCode::kParse,
                     "assimp stopped reading it without an answer (exit status " +
                         std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
                         "): the file is malformed, or of a kind assimp cannot read");
  }
  switch (h.status) {
    case ReplyHeader::kRead:
      break;
    case ReplyHeader::kNoLibrary:
      return fileError(path, ErrorCode::kIo,
                       "FBX and COLLADA files are read by assimp, which could not be loaded (" + message +
                           "); on Debian: apt-get install libassimp5");
    case ReplyHeader::kTooMany:
      return fileError(path, ErrorCode::kTooLarge, message);
    case ReplyHeader::kNoMesh:
      return fileError(path, ErrorCode::kEmptyMesh, message);
    default:
      return fileError(path, ErrorCode::kParse, "assimp: " + message);
  }
  for (const core::Vec3& p : raw.vertices)
    if (!p.allFinite()) return fileError(path, ErrorCode::kNonFinite, "a vertex is not finite");
  for (const std::uint32_t c : raw.corners)
    if (c >= raw.vertices.size())
      return fileError(path, ErrorCode::kIndexOutOfRange, "a face's corner is not a vertex");
  if (raw.ends.empty()) return fileError(path, ErrorCode::kEmptyMesh, "no triangle in the scene");
  if (report) {
    report->meshInstances = h.meshInstances;
    report->primitivesSkipped = h.skipped;
    report->unit = h.unit;
  }
  return raw;
}

}  // namespace shapedb::io::detail
