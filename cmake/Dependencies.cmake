# Every third-party library comes from Debian 12's packages (see scripts/setup.sh).
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB)  # Debian ships FindOpenVDB.cmake only

find_package(Threads REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(OpenVDB REQUIRED)
find_package(Eigen3 3.4 CONFIG REQUIRED)
find_package(Spectra CONFIG REQUIRED)
find_package(OpenMesh CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(nlohmann_json 3.11 CONFIG REQUIRED)
find_package(TinyGLTF CONFIG REQUIRED)  # glTF 2.0 files (io_mesh)
# FBX and COLLADA files (io_mesh): assimp's C API headers. Its library is not linked: a worker process
# loads it at run time (io/src/assimp_reader.h), so that its own copy of tinygltf, in libdraco, never
# meets the one above.
find_path(SHAPEDB_ASSIMP_INCLUDE_DIR assimp/cimport.h REQUIRED)
find_package(SQLite3 REQUIRED)
find_package(ZLIB REQUIRED)  # CRC-32 of the database blobs
find_package(PkgConfig REQUIRED)
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)
# Optional: Bullet for the rigid-body scenario (shapedb drop). Without it, everything else builds.
option(SHAPEDB_WITH_BULLET "Build the rigid-body scenario if Bullet (libbullet-dev) is found" ON)
if(SHAPEDB_WITH_BULLET)
  pkg_check_modules(BULLET QUIET IMPORTED_TARGET bullet)
endif()
set(SHAPEDB_HAVE_BULLET ${BULLET_FOUND})
message(STATUS "shapedb: rigid-body scenario (Bullet): ${BULLET_FOUND}")

# Optional: the database build on MPI (OpenMPI from Debian). Without it, everything else builds.
option(SHAPEDB_WITH_MPI "Build the MPI database build (build --mpi) if MPI is found" ON)
set(SHAPEDB_HAVE_MPI OFF)
if(SHAPEDB_WITH_MPI)
  find_package(MPI QUIET COMPONENTS CXX)
  set(SHAPEDB_HAVE_MPI ${MPI_CXX_FOUND})
endif()
message(STATUS "shapedb: MPI build (build --mpi): ${SHAPEDB_HAVE_MPI}")

# Optional: the Python module (pybind11 and NumPy from Debian, for Debian's own interpreter: another
# python3 first on PATH would not have them). Without them, everything else builds.
option(SHAPEDB_WITH_PYTHON "Build the Python module if pybind11 and NumPy are found" ON)
set(SHAPEDB_HAVE_PYTHON OFF)
if(SHAPEDB_WITH_PYTHON)
  if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python_EXECUTABLE /usr/bin/python3)
  endif()
  find_package(Python 3 QUIET COMPONENTS Interpreter Development.Module)
  if(Python_FOUND)
    find_package(pybind11 2.10 CONFIG QUIET)
    execute_process(COMMAND ${Python_EXECUTABLE} -c "import numpy" RESULT_VARIABLE numpy_missing
                    OUTPUT_QUIET ERROR_QUIET)
    if(pybind11_FOUND AND numpy_missing EQUAL 0)
      set(SHAPEDB_HAVE_PYTHON ON)
    endif()
  endif()
endif()
message(STATUS "shapedb: Python module (pybind11, NumPy): ${SHAPEDB_HAVE_PYTHON}")

find_path(TETGEN_INCLUDE_DIR tetgen.h REQUIRED)
find_library(TETGEN_LIBRARY NAMES tet REQUIRED)
if(NOT TARGET TetGen::tet)
  add_library(TetGen::tet UNKNOWN IMPORTED)
  set_target_properties(TetGen::tet PROPERTIES
    IMPORTED_LOCATION "${TETGEN_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${TETGEN_INCLUDE_DIR}"
    INTERFACE_COMPILE_DEFINITIONS TETLIBRARY)
endif()
# CHOLMOD (SuiteSparse), the supernodal sparse Cholesky of the modal analysis: Debian 12's package has
# neither a CMake package nor pkg-config files.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY NAMES cholmod REQUIRED)
find_library(SUITESPARSE_CONFIG_LIBRARY NAMES suitesparseconfig REQUIRED)
if(NOT TARGET SuiteSparse::cholmod)
  add_library(SuiteSparse::cholmod UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::cholmod PROPERTIES
    IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${SUITESPARSE_CONFIG_LIBRARY}")
endif()

if(SHAPEDB_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(SHAPEDB_BUILD_BENCH)
  find_package(benchmark CONFIG REQUIRED)
endif()
