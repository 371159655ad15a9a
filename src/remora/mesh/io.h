// Reading and writing mesh files: OBJ, OFF, PLY (ascii and binary, `element face` or
// `element tristrips`), STL (ascii and binary).
//
// Reading is two steps: read_soup() parses a file into a PolygonSoup exactly as stored, and
// repair_soup() (repair.h) builds the half-edge Mesh, counting every change. read_mesh() does both.
// Every malformed file is an IoError naming the file and, where known, the line (text formats) or
// byte offset (binary formats): NaN/Inf coordinates, out-of-range or negative indices, truncated or
// garbage content, a header whose counts disagree with the data, an empty mesh, an unknown
// extension.
//
// Writing encodes the whole file in memory (write_mesh_to_memory(), one writer per format), then
// write_mesh() puts it in a temporary file in the target's folder that is renamed over the target
// only when everything was written; a failed write throws IoError and leaves no file behind.
#pragma once

#include <string>
#include <string_view>

#include "remora/mesh/mesh.h"
#include "remora/mesh/repair.h"
#include "remora/mesh/soup.h"

namespace remora {

enum class MeshFormat { Obj, Off, Ply, Stl };

/// The format named by a path's extension (case-insensitive: .obj .off .ply .stl).
/// Throws IoError for any other extension.
MeshFormat format_from_path(const std::string& path);

/// Parses a file into a soup, exactly as stored (no welding, no dropping). Throws IoError, also
/// for a file over `limits`.
SoupFile read_soup(const std::string& path, const ReadLimits& limits = {});

/// Parses bytes already in memory; `name` is used in error messages (e.g. an upload's file name).
SoupFile read_soup_from_memory(std::string_view bytes, MeshFormat format, const std::string& name,
                               const ReadLimits& limits = {});

/// A mesh read from a file and repaired, with the full account of what was changed.
struct LoadResult {
  Mesh mesh;
  LoadReport report;
  /// For every vertex of `mesh` (by index), the index of the file's vertex it came from.
  std::vector<std::uint32_t> source_vertex;
};

/// read_soup() followed by repair_soup(). Throws IoError for a malformed file, a file over
/// `limits`, and when nothing is left to load (an empty mesh).
LoadResult read_mesh(const std::string& path, const RepairOptions& options = {},
                     const ReadLimits& limits = {});
LoadResult read_mesh_from_memory(std::string_view bytes, MeshFormat format, const std::string& name,
                                 const RepairOptions& options = {}, const ReadLimits& limits = {});

struct WriteOptions {
  bool binary = true; ///< PLY and STL: binary (default) or ascii. OBJ and OFF are always text.
};

/// The whole file of `mesh` in `format`: the non-deleted vertices in index order (compact ids)
/// and faces. Text formats print coordinates with 17 significant digits, so doubles round-trip
/// exactly; binary PLY stores doubles; STL stores 32-bit floats (the format allows nothing else).
/// Throws IoError naming `name` for a non-finite coordinate (which no reader would accept).
std::string write_mesh_to_memory(const Mesh& mesh, MeshFormat format, const std::string& name,
                                 const WriteOptions& options = {});

/// Writes write_mesh_to_memory()'s bytes for the format of `path`'s extension, atomically
/// (temporary file + rename): the file holds exactly those bytes or is left as it was.
/// Throws IoError (unknown extension, unwritable folder, non-finite coordinate, disk full).
void write_mesh(const std::string& path, const Mesh& mesh, const WriteOptions& options = {});

} // namespace remora
