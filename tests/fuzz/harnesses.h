#pragma once
// The fuzz harnesses' entry functions: each feeds bytes to one of lvox's input readers.
// They are compiled twice: into the libFuzzer executables of the LVOX_FUZZ build
// (fuzz_main.cpp) and, without libFuzzer, into the test that replays the committed corpora
// (test_corpus_replay.cpp). The contract they check is the one of every reader: it returns
// or throws lvox::InputError; any other exception, a crash or a sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace lvox::fuzz {

using Entry = void (*)(const uint8_t* data, size_t size);

void sceneJson(const uint8_t* data, size_t size);  // parseScene (text; files beside it)
void objMtl(const uint8_t* data, size_t size);     // loadObj; bytes after a NUL are the MTL
void ply(const uint8_t* data, size_t size);        // loadPly
void vdb(const uint8_t* data, size_t size);        // loadVdbGrid, grid "density"
void exr(const uint8_t* data, size_t size);        // readExr

struct Harness {
  std::string_view name;  // also the folder of its corpus: tests/fuzz/corpus/<name>
  Entry entry;
};

// Every harness, in a fixed order.
std::span<const Harness> harnesses();

}  // namespace lvox::fuzz
