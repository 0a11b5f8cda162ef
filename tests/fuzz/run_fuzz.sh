#!/usr/bin/env bash
# Fuzzes one reader with libFuzzer for a set time (docs/hardening.md):
#   tests/fuzz/run_fuzz.sh scene|obj|ply|vdb|exr SECONDS
# Builds build-fuzz/ with clang (-DLVOX_FUZZ=ON: ASan + UBSan + coverage), installing
# clang and libFuzzer's runtime if they are missing (only this script needs them), then
# runs the harness on the committed seeds and crash inputs. New coverage goes to
# build-fuzz/fuzz-work/HARNESS/corpus (not committed); crashes, timeouts (> 10 s per input)
# and inputs over 2 GB of memory go to build-fuzz/fuzz-work/HARNESS/artifacts/. libFuzzer
# runs in fork mode so that it goes on after a finding for the whole time. A finding, once
# fixed, is committed (minimised) to tests/fuzz/corpus/HARNESS/, which ctest replays.
set -euo pipefail
cd "$(dirname "$0")/../.."

harness=${1:?usage: tests/fuzz/run_fuzz.sh scene|obj|ply|vdb|exr SECONDS}
seconds=${2:?usage: tests/fuzz/run_fuzz.sh HARNESS SECONDS}
case "$harness" in scene | obj | ply | vdb | exr) ;; *)
  echo "unknown harness '$harness' (scene, obj, ply, vdb, exr)" >&2
  exit 2
  ;;
esac

missing=()
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

build=${LVOX_FUZZ_BUILD_DIR:-build-fuzz}
if [ ! -f "$build/build.ninja" ]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_CXX_COMPILER=clang++ \
    -DLVOX_FUZZ=ON -DLVOX_BUILD_BENCHMARKS=OFF >/dev/null
fi
cmake --build "$build" -j "${LVOX_JOBS:-2}" --target "fuzz_$harness"

work="$build/fuzz-work/$harness"
mkdir -p "$work/corpus" "$work/artifacts"
dict=()
if [ -f "tests/fuzz/$harness.dict" ]; then dict=(-dict="tests/fuzz/$harness.dict"); fi
corpus=("$work/corpus" "tests/fuzz/seeds/$harness")
if [ -d "tests/fuzz/corpus/$harness" ]; then corpus+=("tests/fuzz/corpus/$harness"); fi

# Leaks inside uninstrumented system libraries are out of reach: .ci/lsan.supp.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/.ci/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
"$build/tests/fuzz/fuzz_$harness" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
  -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=16384 \
  -artifact_prefix="$work/artifacts/" -print_final_stats=1 "${dict[@]}" "${corpus[@]}"
echo "run_fuzz: artifacts in $work/artifacts:" >&2
ls -la "$work/artifacts" >&2
