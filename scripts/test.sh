#!/usr/bin/env bash
# The README's test command: install missing packages, build (Release), run the whole test suite,
# the web viewer's browser test and every fuzz target for a bounded time (docs/testing.md).
# With --sanitize, a second build under AddressSanitizer + UndefinedBehaviorSanitizer runs it too.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs=$(nproc)
# A compiler cache: a rebuild of an unchanged file is a cache hit (a second run of this script on
# the same machine, or CI right after a developer's build); on a fresh machine it costs nothing.
# base_dir makes the cached objects independent of the checkout's path.
launcher=()
if command -v ccache >/dev/null 2>&1; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
  # The sanitizer and fuzz builds carry debug info (-g, -g1), for which ccache by default also
  # hashes the build directory: every fresh clone missed the cache for them (a cold fuzz build
  # is ~15 min on 2 cores). Their debug paths may then name the checkout that filled the cache.
  export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-1}"
fi
# The Python package (python/, docs/python.md) is built in this Release pass only: Debian's
# interpreter, whose python3-numpy it uses (a pyenv or conda python3 may come first on PATH).
python="$(realpath "${CLOD_PYTHON:-/usr/bin/python3}")"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCLOD_BUILD_TESTS=ON \
  -DCLOD_BUILD_PYTHON=ON -DPython_EXECUTABLE="$python" "${launcher[@]}"
cmake --build build -j "$jobs"
ctest --test-dir build -j "$jobs" --output-on-failure  # includes python/pytest (tests/python)
# The README's one-command install of the Python package, into a throwaway virtual environment,
# reusing build/ (only the module's target is checked); then `import clod` from another directory.
rm -rf build/venv
"$python" -m venv --system-site-packages build/venv
CLOD_CMAKE_BUILD_DIR="$PWD/build" build/venv/bin/pip install -q --no-build-isolation .
(cd / && "$OLDPWD/build/venv/bin/python" -c 'import clod; print("python: import clod", clod.__version__, "from", clod.__file__)')
scripts/test-viewer.sh build/bin/clod  # the web viewer in headless Chromium (docs/viewer.md)
# Fuzzing (fuzz/, docs/testing.md): each reader of user files under libFuzzer + ASan + UBSan for
# CLOD_FUZZ_SECONDS (default 10) from its seed corpus, built with clang 16 in build-fuzz/ (ccache);
# a crash, sanitizer report, hang or runaway allocation fails the script. CLOD_FUZZ_SECONDS=0 skips it.
if [[ "${CLOD_FUZZ_SECONDS:-10}" != 0 ]]; then
  scripts/install-deps.sh --fuzz
  scripts/fuzz.sh
fi
if [[ "${1:-}" == "--sanitize" ]]; then
  # The library's own tests under the sanitizers; the CLI's end-to-end tests ran in Release above
  # (CLOD_BUILD_CLI, CMakeLists.txt says why), and so did the engine plug-ins' (CLOD_BUILD_ENGINES).
  # With clod's layers as shared libraries (CLOD_BUILD_SHARED): the Release pass tests the static
  # ones and their install, this one that every test runs against the .so files.
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCLOD_SANITIZE=ON -DCLOD_BUILD_TESTS=ON \
    -DCLOD_BUILD_CLI=OFF -DCLOD_BUILD_ENGINES=OFF -DCLOD_BUILD_SHARED=ON "${launcher[@]}"
  cmake --build build-asan -j "$jobs"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 CLOD_TEST_SCALE=sanitizer \
    ctest --test-dir build-asan -j "$jobs" --output-on-failure
fi
