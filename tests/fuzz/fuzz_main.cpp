// libFuzzer entry point of one harness (LVOX_FUZZ build): LVOX_FUZZ_ENTRY names the
// function of harnesses.h. An InputError is the reader doing its job; any other exception
// escapes, terminates the process and so is reported as a crash with its input.
#include "harnesses.h"
#include "src/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lvox::fuzz::LVOX_FUZZ_ENTRY(data, size);
  } catch (const lvox::InputError&) {
  }
  return 0;
}
