#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang in their own build folder and runs each for a
# bounded time from its seed corpus (fuzz/corpus/<target>/). A crash, a sanitizer report, a
# timeout or an out-of-memory in any target fails the script (non-zero exit) and leaves the
# reproducer in build-fuzz/findings/<target>/. scripts/test.sh runs it; docs/testing.md says more.
#   scripts/fuzz.sh [SECONDS_PER_TARGET]     default 10 (CLOD_FUZZ_SECONDS overrides too)
# Reproduce a finding: build-fuzz/bin/<target> build-fuzz/findings/<target>/crash-...
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-${CLOD_FUZZ_SECONDS:-10}}"
# clang 16 (Debian bookworm's clang-16): clang 14, bookworm's default, cannot compile the C++20
# lambdas that capture structured bindings (src/dynamics/world.cpp, src/sphere_tree/).
cxx="${CLOD_FUZZ_CXX:-clang++-16}"
command -v "$cxx" >/dev/null || { echo "fuzz.sh: $cxx missing (scripts/install-deps.sh --fuzz)" >&2; exit 1; }
launcher=()
if command -v ccache >/dev/null 2>&1; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
  # The sanitizer and fuzz builds carry debug info (-g, -g1), for which ccache by default also
  # hashes the build directory: every fresh clone missed the cache for them (a cold fuzz build
  # is ~15 min on 2 cores). Their debug paths may then name the checkout that filled the cache.
  export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
fi
# Only the layers the targets read with: no tests, CLI, engines or Python. -O1 as the sanitizer
# build (cmake/ClodWarnings.cmake): faster to compile, what the sanitizers' documentation suggests.
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$cxx" \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DCLOD_BUILD_FUZZERS=ON -DCLOD_BUILD_TESTS=OFF \
  -DCLOD_BUILD_CLI=OFF -DCLOD_BUILD_ENGINES=OFF -DCLOD_WITH_MUJOCO=OFF -DCLOD_BUILD_PYTHON=OFF "${launcher[@]}" >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target fuzzers
failed=()
for corpus in fuzz/corpus/*/; do
  target=$(basename "$corpus")
  findings="build-fuzz/findings/$target"
  work="build-fuzz/corpus/$target"  # new inputs go here, never into the repository's seeds
  rm -rf "$findings" && mkdir -p "$findings" "$work"
  echo "fuzz.sh: $target for ${seconds}s"
  # -timeout: one input taking over 10 s is a hang; -rss_limit_mb: a reader that allocates without
  # bound is a bug too (the loaders check resource limits before they allocate).
  # Leaks count too, except those inside Debian's libraries (fuzz/lsan.supp says which and why).
  if ! ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=fuzz/lsan.supp:print_suppressions=0 \
      UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "build-fuzz/bin/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$findings/" -print_final_stats=1 "$work" "$corpus" >"$findings/log.txt" 2>&1; then
    failed+=("$target")
    tail -n 40 "$findings/log.txt" >&2
  fi
  grep -E "^(stat::number_of_executed_units|stat::peak_rss_mb)" "$findings/log.txt" | tr '\n' ' ' || true
  echo
done
if ((${#failed[@]})); then
  echo "fuzz.sh: FAILED: ${failed[*]} (reproducers in build-fuzz/findings/)" >&2
  exit 1
fi
echo "fuzz.sh: all targets ran ${seconds}s without a finding"
