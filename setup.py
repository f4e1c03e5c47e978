"""Builds the Python package clod: CMake builds the module clod._clod, setuptools packages it.

One command from the repository (Debian 12, offline; see docs/python.md):
    python3 -m venv --system-site-packages .venv && .venv/bin/pip install --no-build-isolation .

Environment:
    CLOD_CMAKE_BUILD_DIR  the CMake build folder to use (default: build-python/ in the checkout); an
                          existing one (e.g. build/ of scripts/test.sh) is reused, so only the
                          module's target is built
    CLOD_BUILD_JOBS       parallel compile jobs (default: the CPU count)
"""

import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
os.makedirs(os.path.join(ROOT, "build-python"), exist_ok=True)  # setup.cfg puts setuptools' scratch there
with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as cmake_lists:
    VERSION = re.search(r"project\(clod VERSION ([0-9.]+)", cmake_lists.read()).group(1)


class CMakeBuild(build_ext):
    """Configures and builds the CMake target clod_python, then copies the module into place."""

    def build_extension(self, ext):
        build_dir = os.path.abspath(os.environ.get("CLOD_CMAKE_BUILD_DIR") or os.path.join(ROOT, "build-python"))
        configured = os.path.isfile(os.path.join(build_dir, "CMakeCache.txt"))
        # The base interpreter behind a virtual environment's symlink: same headers and ABI, and the
        # same path the test script configures with, so reusing its build folder reconfigures nothing.
        python = os.path.realpath(sys.executable)
        configure = ["cmake", "-S", ROOT, "-B", build_dir, "-DCLOD_BUILD_PYTHON=ON", f"-DPython_EXECUTABLE={python}"]
        if not configured:
            configure += ["-DCMAKE_BUILD_TYPE=Release", "-DCLOD_BUILD_TESTS=OFF", "-DCLOD_BUILD_CLI=OFF"]
            if shutil.which("ninja"):
                configure += ["-G", "Ninja"]
            if shutil.which("ccache"):
                configure += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
        env = dict(os.environ)
        env.setdefault("CCACHE_BASEDIR", ROOT)
        subprocess.check_call(configure, env=env)
        jobs = os.environ.get("CLOD_BUILD_JOBS") or str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", build_dir, "--target", "clod_python", "-j", jobs], env=env)
        built = glob.glob(os.path.join(build_dir, "python", "clod", "_clod*.so"))
        if len(built) != 1:
            raise RuntimeError(f"expected one compiled module in {build_dir}/python/clod, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)


setup(
    version=VERSION,
    packages=["clod"],
    package_dir={"": "python"},
    package_data={"clod": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("clod._clod", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
