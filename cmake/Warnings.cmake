# shapedb_warnings: the warning set for shapedb's own code (third-party headers come in as -isystem).
add_library(shapedb_warnings INTERFACE)
target_compile_options(shapedb_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align
  -Woverloaded-virtual -Wimplicit-fallthrough
  $<$<BOOL:${SHAPEDB_WERROR}>:-Werror>)

# shapedb_add_module(name SOURCES ... DEPENDS ...): one library per top-level folder, shapedb::<name>.
function(shapedb_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPENDS;PRIVATE_DEPENDS" ${ARGN})
  add_library(shapedb_${name} STATIC ${ARG_SOURCES})
  add_library(shapedb::${name} ALIAS shapedb_${name})
  target_include_directories(shapedb_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>)
  target_link_libraries(shapedb_${name} PUBLIC ${ARG_PUBLIC_DEPENDS} PRIVATE ${ARG_PRIVATE_DEPENDS}
    $<BUILD_INTERFACE:shapedb_warnings>)
  set_target_properties(shapedb_${name} PROPERTIES OUTPUT_NAME shapedb_${name} POSITION_INDEPENDENT_CODE ON
    EXPORT_NAME ${name})
  if(SHAPEDB_NATIVE_ARCH)
    # Eigen's fixed-size types change layout and alignment with the vector ISA: code that includes our
    # headers must be compiled for the same one, or it reads our structs wrongly (it crashed).
    target_compile_options(shapedb_${name} INTERFACE -march=native)
  endif()
  install(TARGETS shapedb_${name} EXPORT shapedbTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# GCC 12's -Wmaybe-uninitialized is wrong about our code in every optimized build: its AVX-512 intrinsics
# trip it wherever Eigen's packet code is inlined (GCC bug 105593, fixed in GCC 13; -march=native builds),
# and at -O2 and -O3 it takes the disengaged std::optional<Upgrade> of a moved AugmentedObject for an
# uninitialized std::function (GCC bug 80635; the haptic loop, in a portable build). Clang's presets and
# GCC's -Wuninitialized still check.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(shapedb_warnings INTERFACE -Wno-maybe-uninitialized)
endif()
