#!/usr/bin/env bash
# tests/fuzz/run.sh [SECONDS] — fuzz the scene loader, the event parser and the
# manifest reader with libFuzzer.
#
# Configures a separate build directory with clang (-DSPH2D_FUZZ=ON: the
# engine and the target built with -fsanitize=fuzzer,address,undefined),
# builds tests/fuzz/fuzz_scene.cpp and runs it for SECONDS (default 60) from
# the seed corpus tests/fuzz/corpus (new inputs go to BUILD/fuzz-corpus, the
# checked-in corpus is never written). Exits non-zero on any crash, leak,
# timeout, out-of-memory or sanitizer report; the failing input is saved as
# BUILD/fuzz-artifacts/crash-* (replay it: BUILD/tests/sph2d_fuzz_scene FILE).
#
# Environment: SPH2D_FUZZ_BUILD (build dir, default build-fuzz),
# SPH2D_FUZZ_CXX (clang++), SPH2D_FUZZ_SEED (libFuzzer -seed, default random),
# SPH2D_FUZZ_JOBS (compile jobs, default 2).
set -euo pipefail
secs="${1:-60}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${SPH2D_FUZZ_BUILD:-$root/build-fuzz}"
cxx="${SPH2D_FUZZ_CXX:-$(command -v clang++-14 || command -v clang++ || true)}"
if [ -z "$cxx" ]; then
  echo "run.sh: clang++ not found (Debian: apt-get install clang-14 libclang-rt-14-dev)" >&2
  exit 2
fi
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$cxx" \
  -DSPH2D_FUZZ=ON -DSPH2D_BUILD_RENDER=OFF >/dev/null
cmake --build "$build" --target sph2d_fuzz_scene -j"${SPH2D_FUZZ_JOBS:-2}"
mkdir -p "$build/fuzz-corpus" "$build/fuzz-artifacts"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
echo "run.sh: fuzzing the scene loader, event parser and manifest reader for ${secs} s"
exec "$build/tests/sph2d_fuzz_scene" "$build/fuzz-corpus" "$root/tests/fuzz/corpus" \
  -dict="$root/tests/fuzz/scene.dict" -max_total_time="$secs" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$build/fuzz-artifacts/" -print_final_stats=1 ${SPH2D_FUZZ_SEED:+-seed="$SPH2D_FUZZ_SEED"}
