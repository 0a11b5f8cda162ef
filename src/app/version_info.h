#pragma once
// The version of lvox and the git revision it was configured from (`lvox --version`, and
// every image's header).
#include <string>

namespace lvox {

std::string versionString();
std::string gitRevision();
std::string versionLine();  // "lvox 0.1.0 (git 0123456789ab)"

}  // namespace lvox
