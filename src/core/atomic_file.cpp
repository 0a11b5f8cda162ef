#include "src/core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

#include "src/core/error.h"

namespace lvox {
namespace {

namespace fs = std::filesystem;

std::string errnoText() { return std::strerror(errno); }

// Creates an empty, unique temporary file next to `path` and returns its name.
std::string createTemporary(const fs::path& path) {
  std::random_device entropy;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = ".";
    name.append(path.filename().string())
        .append(".tmp-")
        .append(std::to_string(getpid()))
        .append("-")
        .append(std::to_string(entropy() % 1000000u));
    const fs::path tmp = path.parent_path() / name;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd >= 0) {
      ::close(fd);
      return tmp.string();
    }
    if (errno != EEXIST)
      throw InputError(path.string(), "", "cannot create a file in its directory: " + errnoText());
  }
  throw InputError(path.string(), "", "cannot create a unique temporary file");
}

void syncPath(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) throw InputError(path, "", "cannot reopen for sync: " + errnoText());
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0 && err != EINVAL)
    throw InputError(path, "", std::string("fsync failed: ") + std::strerror(err));
}

}  // namespace

void publishAtomically(const std::string& path,
                       const std::function<void(const std::string&)>& write,
                       const std::function<void(const std::string&)>& verify) {
  const fs::path target(path);
  const std::string tmp =
      createTemporary(target.parent_path().empty() ? fs::path(".") / target : target);
  try {
    write(tmp);
    syncPath(tmp, O_RDONLY);
    if (verify) verify(tmp);
    if (::rename(tmp.c_str(), path.c_str()) != 0)
      throw InputError(path, "", "cannot rename the finished file into place: " + errnoText());
  } catch (const InputError&) {
    ::unlink(tmp.c_str());
    throw;
  } catch (const std::exception& e) {
    ::unlink(tmp.c_str());
    throw InputError(path, "",
                     std::string("write failed: ") + std::string(e.what()).substr(0, 200));
  }
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  try {
    syncPath(dir.string(), O_RDONLY | O_DIRECTORY);
  } catch (const InputError&) {
    // The file is complete and in place; a directory that cannot be synced (some
    // filesystems refuse) only weakens durability across a power cut.
  }
}

void checkOutputPath(const std::string& path, const std::string& field,
                     const std::vector<std::string>& inputs) {
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(path, field, "the output directory " + dir.string() + " does not exist");
  if (p.filename().empty()) throw InputError(path, field, "is a directory, not a file name");
  const fs::path resolved = fs::weakly_canonical(p, ec);
  for (const std::string& in : inputs) {
    std::error_code ec2;
    if (fs::exists(p, ec2) && fs::exists(in, ec2) && fs::equivalent(p, in, ec2))
      throw InputError(path, field, "would overwrite the input " + in);
    if (!ec && fs::weakly_canonical(in, ec2) == resolved)
      throw InputError(path, field, "would overwrite the input " + in);
  }
}

}  // namespace lvox
