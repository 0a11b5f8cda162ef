// LVOX_FUZZ build only: tinyobjloader's implementation compiled from Debian's header into
// the fuzzers that reach loadObj, so that the OBJ/MTL parser itself is instrumented
// (coverage for libFuzzer, ASan on its buffers). The definitions here are linked before
// Debian's uninstrumented libtinyobjloader and take its place; same source version.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
