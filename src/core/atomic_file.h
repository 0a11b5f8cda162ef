#pragma once
// Publishing a file so that nothing is ever lost: the content goes to a temporary file
// in the same directory (created with O_EXCL), is flushed to disk, optionally verified by
// reading it back, and only then renamed over the destination. On any failure the
// temporary file is removed and the previous destination, if any, stays intact.
#include <functional>
#include <string>
#include <vector>

namespace lvox {

// `write(tmpPath)` writes the content to tmpPath (by path, as OpenEXR and libpng want);
// `verify(tmpPath)`, if given, throws when the written file is unusable. Errors are
// thrown as InputError naming `path`.
void publishAtomically(const std::string& path,
                       const std::function<void(const std::string&)>& write,
                       const std::function<void(const std::string&)>& verify = {});

// Throws InputError(path, field, ...) if the directory of `path` does not exist or `path`
// is the same file as one of `inputs` (compared after resolving links and dots).
void checkOutputPath(const std::string& path, const std::string& field,
                     const std::vector<std::string>& inputs);

}  // namespace lvox
