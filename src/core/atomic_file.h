#pragma once
// Publishing a file so that nothing is ever lost: the content goes to a temporary file
// in the same directory (created with O_EXCL), is flushed to disk, optionally verified by
// reading it back, and only then renamed over the destination. On any failure the
// temporary file is removed and the previous destination, if any, stays intact.
#include <functional>
#include <string>
#include <vector>

namespace lvox {

using WriteFn = std::function<void(const std::string&)>;

// Outputs published together (an image, its preview and its report): each is written to
// its temporary when staged; commit() renames them all into place, back to back. A set
// destroyed before commit() removes its temporaries, and so does SIGINT, SIGTERM or
// SIGHUP arriving while any are staged (the signal is then re-raised), so a failed or
// interrupted command leaves neither a half-published set nor temporaries behind.
class OutputSet {
 public:
  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet();
  // `write(tmpPath)` writes the content to tmpPath (by path, as OpenEXR and libpng want);
  // `verify(tmpPath)`, if given, throws when the written file is unusable. Errors are
  // thrown as InputError naming `path`.
  void stage(const std::string& path, const WriteFn& write, const WriteFn& verify = {});
  void commit();

 private:
  struct Staged {
    std::string path, tmp;
    int slot;  // in the signal handler's table
  };
  void discard();
  std::vector<Staged> staged_;
};

// Unlinks every staged temporary of the process; async-signal-safe, for a program's own
// signal handler (OutputSet installs its own only where none is set).
void removeStagedTemporaries();

// One file, staged and committed at once.
void publishAtomically(const std::string& path,
                       const std::function<void(const std::string&)>& write,
                       const std::function<void(const std::string&)>& verify = {});

// Throws InputError(path, field, ...) if the directory of `path` does not exist or `path`
// is the same file as one of `inputs` (compared after resolving links and dots).
void checkOutputPath(const std::string& path, const std::string& field,
                     const std::vector<std::string>& inputs);

}  // namespace lvox
