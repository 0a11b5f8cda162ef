#include "version.h"

#include "src/app/version_info.h"

namespace lvox {

std::string versionString() { return kLvoxVersion; }
std::string gitRevision() { return kLvoxRevision; }
std::string versionLine() {
  return std::string("lvox ") + kLvoxVersion + " (git " + kLvoxRevision + ")";
}

}  // namespace lvox
