// A stand-in for assimp whose reader crashes on every file, as a malformed file can crash the real one:
// the FBX and COLLADA tests load it through SHAPEDB_ASSIMP to show that the crash stays in the worker.
#include <csignal>

extern "C" {

const void* aiImportFile(const char* /*path*/, unsigned /*flags*/) {
  std::raise(SIGSEGV);
  return nullptr;
}

const char* aiGetErrorString() {
  return "unreachable";
}

}  // extern "C"
