#pragma once
// A walk of an OpenVDB file, in OpenVDB 10's own reading order, before OpenVDB reads it.
//
// OpenVDB trusts what a file says (found by fuzzing, issue 16):
// - it allocates whatever a length field says before reading the bytes: a 500-byte file
//   whose grid name claimed 4 GiB made it allocate (and zero) 4 GiB;
// - it loops over whatever node counts the tree declares, reading on past the end of the
//   file (seconds to minutes, gigabytes);
// - when a tree's topology fails to read (a corrupt compressed block, a short file), it
//   leaks the root child it was reading (up to 69 MB per file), and a root child listed
//   twice leaks the first.
// So every length, count, offset and compressed block is checked here first:
// - the header, the file's metadata, each grid descriptor, each grid's metadata and
//   transform;
// - for the grid that will be read (or the grid it is an instance of), if it holds floats:
//   its whole tree. The topology's compressed blocks (internal nodes' values) are
//   decompressed and must give their exact size, so OpenVDB's topology read cannot throw;
//   the leaves' value blocks are checked for their sizes only (a failure there is thrown
//   after the tree owns its nodes, and frees them).
// A file that passes reads in OpenVDB without an exception inside its topology and
// without reading past the grid's end.
#include <cstdint>
#include <string>

namespace lvox {

// The nodes of the walked tree: what OpenVDB will allocate for it.
struct VdbTreeShape {
  uint64_t rootTiles = 0, upperNodes = 0, lowerNodes = 0, leaves = 0;
  // The bytes OpenVDB 10 allocates for these nodes (float values, leaves' buffers loaded).
  uint64_t bytes() const;
};

// Walks `path` as OpenVDB will read grid `gridName` of it. Throws
// InputError(path, field, "not a readable OpenVDB file: ...") on the first problem. The tree
// is walked when exactly one grid is named `gridName` and it holds floats (else the shape
// is empty and the loader reports the name or type).
VdbTreeShape precheckVdbFile(const std::string& path, const std::string& field,
                             const std::string& gridName);

}  // namespace lvox
