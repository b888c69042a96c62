# Precompiled headers. Every source of core and volume includes Eigen's dense module (through core/types.h)
# and a handful of standard headers: parsing them took 5 s of a typical core source's 7 s, and 2-3 s with
# them precompiled. A precompiled header costs about three sources' parse and must be built before any
# of its target's sources, so only the libraries of many small sources get one: the unity-built tests and
# command-line tool lost more than they won (measured on full release builds). Only third-party and
# standard headers go in, never ours: a source that forgets one of our includes must still fail to compile
# (one that forgets a standard header compiles all the same: -DSHAPEDB_PRECOMPILE_HEADERS=OFF checks that).
option(SHAPEDB_PRECOMPILE_HEADERS "Precompile the common third-party headers of the larger targets" ON)

set(SHAPEDB_COMMON_HEADERS
  <Eigen/Dense> <algorithm> <array> <cmath> <cstdint> <limits> <memory> <optional> <span> <string> <vector>)

# shapedb_precompile(target [HEADER...]): the common headers, and these, precompiled for one target.
function(shapedb_precompile target)
  if(SHAPEDB_PRECOMPILE_HEADERS)
    target_precompile_headers(${target} PRIVATE ${SHAPEDB_COMMON_HEADERS} ${ARGN})
  endif()
endfunction()
