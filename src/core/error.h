#pragma once
// Errors in user input: the message always names the file and, where there is one, the
// field, so the command line can print one clear line and exit non-zero.
#include <stdexcept>
#include <string>

namespace lvox {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(format(file, field, what)) {}

 private:
  static std::string format(const std::string& file, const std::string& field,
                            const std::string& what) {
    std::string s = file;
    if (!field.empty()) s += ": " + field;
    return s + ": " + what;
  }
};

}  // namespace lvox
