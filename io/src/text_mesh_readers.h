#pragma once

// shapedb's own readers for OBJ, OFF and PLY. OpenMesh's readers for these formats are not robust to
// hostile files (found by fuzzing, tests/fuzz): its OBJ reader aborts on a corner without a vertex index
// ("f /1": an assert left on in Debian's build), reads an uninitialized index from a corner it cannot
// parse, and opens whatever file `mtllib` names (a hang on "mtllib /dev/zero"); its PLY reader loops
// forever on a header without end_header, allocates whatever a header's counts say, and reads out of
// bounds on lying list counts; its OFF reader reads garbage indices past a lying count. These readers
// read only the geometry, check every count and index against the bytes there are, and never allocate
// more than the file's size can pay for.

#include <filesystem>

#include <shapedb/core/result.h>

#include "raw_polygons.h"

namespace shapedb::io::detail {

/// Wavefront OBJ: `v` lines (the first three numbers, double precision) and `f` lines (the vertex index
/// of each `v/vt/vn` corner; negative indices count back from the last vertex so far). Every other
/// statement is skipped; no other file is opened (`mtllib` is ignored). Repeated consecutive corners of
/// a polygon are merged. Errors (naming the file and the line): kNonFinite, kParse, kIndexOutOfRange.
Result<RawPolygons> readObj(const std::filesystem::path& path);

/// OFF (ASCII; OFF, COFF, NOFF, CNOFF, STOFF headers): counts, then one vertex per line (the first
/// three numbers; colours and normals after them ignored) and one polygon per line ("k i1 ... ik",
/// colours after it ignored). Errors: kParse (a bad header, fewer lines than the counts say, a number
/// that is not one; binary and 4D/nD OFF are refused), kNonFinite.
Result<RawPolygons> readOff(const std::filesystem::path& path);

/// PLY, ASCII or binary (either byte order): the `vertex` element's x, y, z (any scalar type) and the
/// `face` element's vertex_indices (or vertex_index) list; every other element and property is read
/// past. Errors: kParse (a bad header or a body shorter than its counts), kNonFinite, kIndexOutOfRange
/// (a negative index).
Result<RawPolygons> readPly(const std::filesystem::path& path);

}  // namespace shapedb::io::detail
