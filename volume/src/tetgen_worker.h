#pragma once
// TetGen behind a process boundary (private to the volume module): TetGen aborts, segfaults or loops on
// some inputs, so tetrahedralize runs it in a worker process per thread, fed over a socketpair. This is
// the plumbing; what to ask TetGen and how to check its answer is tetrahedralize.cpp's.

#include <cstdint>
#include <string>
#include <vector>

#include <shapedb/core/result.h>
#include <shapedb/core/triangle_mesh.h>

namespace shapedb::volume::detail {

/// TetGen's output, or why there is none: the plain-data form that crosses the socket from the worker.
struct TetGenOutput {
  std::int32_t status = 0;  ///< 0 ok; otherwise TetGen's error code (its terminatetetgen argument)
  std::vector<double> nodes;
  std::vector<std::int32_t> tets;
};

/// Runs TetGen in this process with these command-line switches. `maxVolumes`, if not empty, holds per
/// triangle of the surface the largest volume of a tet whose centroid is closest to that triangle (+∞:
/// no bound): TetGen's refinement splits any tet over it (its tetunsuitable hook), as it splits a tet
/// over the 'a' bound. `holes`: a point inside each cavity of the solid, whose tets TetGen then removes
/// (its hole list; with 'p' it removes only what lies outside the outer shell). TetGen reports errors by
/// throwing an int (TETLIBRARY builds): they come back as the status.
TetGenOutput runTetGen(const core::TriangleMesh& surface, const std::vector<double>& maxVolumes,
                       const std::vector<core::Vec3>& holes, const std::string& switches);

/// runTetGen in this thread's worker process, forked on first use and reused. A worker that crashes, or
/// does not answer within `timeoutSeconds`, costs this request only (a kIo error that says which); the
/// next request forks a fresh worker.
Result<TetGenOutput> runTetGenGuarded(const core::TriangleMesh& surface,
                                      const std::vector<double>& maxVolumes,
                                      const std::vector<core::Vec3>& holes, const std::string& switches,
                                      double timeoutSeconds);

/// TetGen's error codes (terminatetetgen in tetgen.cxx), in words.
std::string describeTetGenError(int code);

}  // namespace shapedb::volume::detail
