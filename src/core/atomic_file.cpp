#include "src/core/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <mutex>
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

void removeStagedTemporaries();

namespace {

// Temporaries staged anywhere in the process, for the signal handler: fixed storage, so
// the handler only reads memory and calls unlink (both async-signal-safe).
constexpr int kMaxStaged = 64;
char g_stagedPath[kMaxStaged][4096];
std::atomic<bool> g_stagedUsed[kMaxStaged];
std::once_flag g_handlersInstalled;

extern "C" void removeStagedAndReraise(int sig) {
  removeStagedTemporaries();
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

void installHandlers() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction current {};
    ::sigaction(sig, nullptr, &current);
    // A handler the program installed itself is left alone.
    if (current.sa_handler != SIG_DFL) continue;
    struct sigaction action {};
    action.sa_handler = removeStagedAndReraise;
    sigemptyset(&action.sa_mask);
    ::sigaction(sig, &action, nullptr);
  }
}

int registerStaged(const std::string& tmp) {
  std::call_once(g_handlersInstalled, installHandlers);
  if (tmp.size() >= sizeof g_stagedPath[0]) return -1;
  for (int i = 0; i < kMaxStaged; ++i) {
    if (g_stagedUsed[i].load()) continue;
    std::memcpy(g_stagedPath[i], tmp.c_str(), tmp.size() + 1);
    bool expected = false;
    if (g_stagedUsed[i].compare_exchange_strong(expected, true)) return i;
  }
  return -1;  // more than kMaxStaged at once: still removed on failure, not on a signal
}

void unregisterStaged(int slot) {
  if (slot >= 0) g_stagedUsed[slot].store(false);
}

}  // namespace

void removeStagedTemporaries() {
  for (int i = 0; i < kMaxStaged; ++i)
    if (g_stagedUsed[i].load()) ::unlink(g_stagedPath[i]);
}

OutputSet::~OutputSet() { discard(); }

void OutputSet::discard() {
  for (const Staged& s : staged_) {
    ::unlink(s.tmp.c_str());
    unregisterStaged(s.slot);
  }
  staged_.clear();
}

void OutputSet::stage(const std::string& path, const WriteFn& write, const WriteFn& verify) {
  const fs::path target(path);
  const std::string tmp =
      createTemporary(target.parent_path().empty() ? fs::path(".") / target : target);
  const int slot = registerStaged(tmp);
  staged_.push_back({path, tmp, slot});
  try {
    write(tmp);
    syncPath(tmp, O_RDONLY);
    if (verify) verify(tmp);
  } catch (const InputError&) {
    discard();
    throw;
  } catch (const std::exception& e) {
    discard();
    throw InputError(path, "",
                     std::string("write failed: ") + std::string(e.what()).substr(0, 200));
  }
}

void OutputSet::commit() {
  std::error_code ec;
  for (const Staged& s : staged_)
    if (fs::is_directory(s.path, ec)) {
      const std::string path = s.path;
      discard();
      throw InputError(path, "", "is a directory");
    }
  for (const Staged& s : staged_) {
    if (::rename(s.tmp.c_str(), s.path.c_str()) != 0) {
      const std::string path = s.path;
      discard();
      throw InputError(path, "", "cannot rename the finished file into place: " + errnoText());
    }
    unregisterStaged(s.slot);
  }
  for (const Staged& s : staged_) {
    const fs::path target(s.path);
    const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    try {
      syncPath(dir.string(), O_RDONLY | O_DIRECTORY);
    } catch (const InputError&) {
      // The file is complete and in place; a directory that cannot be synced (some
      // filesystems refuse) only weakens durability across a power cut.
    }
  }
  staged_.clear();
}

void publishAtomically(const std::string& path, const WriteFn& write, const WriteFn& verify) {
  OutputSet set;
  set.stage(path, write, verify);
  set.commit();
}

void checkOutputPath(const std::string& path, const std::string& field,
                     const std::vector<std::string>& inputs) {
  const fs::path p(path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(path, field, "the output directory " + dir.string() + " does not exist");
  if (p.filename().empty() || fs::is_directory(p, ec))
    throw InputError(path, field, "is a directory, not a file name");
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
