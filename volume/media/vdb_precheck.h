#pragma once
// A check of the lengths an OpenVDB file declares before OpenVDB reads it. OpenVDB 10
// allocates whatever a length field says before it reads the bytes: a 500-byte file whose
// grid name claims 4 GiB made it allocate (and zero) 4 GiB (found by fuzzing, issue 16).
// This walks the parts that are read before any grid data, in OpenVDB's own order: the
// header, the file's metadata, each grid descriptor, each grid's metadata and the type name
// of its transform. Every string and metadata value must fit in the file, every grid's
// offsets must lie inside it, in order. The trees themselves are left to OpenVDB.
#include <string>

namespace lvox {

// Throws InputError(path, field, "not a readable OpenVDB file: ...") on the first problem.
void precheckVdbFile(const std::string& path, const std::string& field);

}  // namespace lvox
