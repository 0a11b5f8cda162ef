# Instrumented builds, both off by default (the normal build needs neither clang nor the
# sanitizer runtimes):
#   LVOX_SANITIZE  AddressSanitizer + UndefinedBehaviorSanitizer over every target, for the
#                  second run of the test suite (.ci/sanitize, build-asan/).
#   LVOX_FUZZ      the libFuzzer harnesses of tests/fuzz (clang only): every target gets
#                  coverage instrumentation and the same sanitizers (tests/fuzz/run_fuzz.sh).
# Debian's TBB, OpenVDB, Embree, OpenEXR and assimp stay uninstrumented: the sanitizers
# see our code and what it passes to them.
option(LVOX_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(LVOX_FUZZ "Build the libFuzzer harnesses of tests/fuzz (needs clang)" OFF)

# UBSan reports are fatal (-fno-sanitize-recover), so a test that triggers one fails.
set(lvox_sanitizer_flags -fsanitize=address,undefined -fno-sanitize-recover=undefined
                         -fno-omit-frame-pointer)

# Clang reads the ignorelist of checks that fire inside system headers we cannot change.
if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  list(APPEND lvox_sanitizer_flags
       "-fsanitize-ignorelist=${CMAKE_CURRENT_LIST_DIR}/ubsan_ignorelist.txt")
endif()

if(LVOX_SANITIZE)
  add_compile_options(${lvox_sanitizer_flags})
  add_link_options(-fsanitize=address,undefined)
  # Environment of every test (tests/CMakeLists.txt adds it to each test's ENVIRONMENT;
  # the lvox binary that the app tests start inherits it):
  #  - halt_on_error, abort_on_error=0: the first report ends the test, non-zero exit.
  #  - detect_leaks=1: LeakSanitizer at exit, with the suppressions of .ci/lsan.supp
  #    (leaks inside uninstrumented system libraries that the project cannot fix).
  #  - print_stacktrace=1: UBSan reports name the call chain, not only the line.
  set(LVOX_SANITIZER_ENV
      "ASAN_OPTIONS=halt_on_error=1:abort_on_error=0:detect_leaks=1:check_initialization_order=1:strict_init_order=1"
      "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/.ci/lsan.supp:print_suppressions=0"
      "UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1")
endif()

if(LVOX_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "LVOX_FUZZ needs clang (libFuzzer): configure with "
                        "-DCMAKE_CXX_COMPILER=clang++, as tests/fuzz/run_fuzz.sh does")
  endif()
  # fuzzer-no-link: coverage feedback from our code; the harness executables add
  # -fsanitize=fuzzer (libFuzzer's main) themselves.
  add_compile_options(-fsanitize=fuzzer-no-link ${lvox_sanitizer_flags})
  add_link_options(-fsanitize=address,undefined)
endif()
