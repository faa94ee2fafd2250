"""`pip install --no-build-isolation ./python`: builds twincal's extension with the checkout's
CMake project (docs/python.md, "Install with pip") and installs it with the pure-Python package.

The extension is the CMake target ``twincal_python``. By default it is configured and built in
``python/build/cmake`` (kept, so the next install only rebuilds what changed) with the
project's libraries, in Release, for the interpreter that runs pip. Environment:

- ``TWINCAL_CMAKE_BUILD_DIR``: an existing, configured build directory of this checkout (e.g.
  ``build``, which ``./scripts/test.sh`` makes) to build the target in instead, so that an
  install reuses what that build compiled: an absolute path, and the build's interpreter must
  be the one running pip.
- ``CMAKE_GENERATOR``, ``CXX``: as CMake reads them; without them, Ninja, Clang 14 (which
  compiles the template-heavy sources 2.4x faster than GCC 12) and ccache are used when found.
- ``TWINCAL_PIP_JOBS``: parallel compile jobs (default: the cores).
"""

import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

PACKAGE_DIR = Path(__file__).resolve().parent
SOURCE_DIR = PACKAGE_DIR.parent


def project_version():
    """The version of the CMake project, the package's single source of it."""
    cmake_lists = SOURCE_DIR / "CMakeLists.txt"
    match = re.search(r"project\(twincal\s+VERSION\s+([0-9][0-9.]*)", cmake_lists.read_text())
    if match is None:
        raise RuntimeError(f"{cmake_lists}: no 'project(twincal VERSION x.y.z' to take the "
                           "package's version from")
    return match.group(1)


def cache_value(build_dir, name):
    """The value of `name` in build_dir's CMakeCache.txt, or None."""
    for line in (build_dir / "CMakeCache.txt").read_text().splitlines():
        key, _, value = line.partition("=")
        if key.split(":")[0] == name:
            return value
    return None


class CMakeExtension(Extension):
    """An extension that CMake builds: no sources of its own for setuptools."""

    def __init__(self, name, target):
        super().__init__(name, sources=[])
        self.target = target


class CMakeBuild(build_ext):
    """Configures (unless reusing a build directory) and builds each extension's CMake target,
    then copies the module where setuptools packs it."""

    def build_extension(self, ext):
        build_dir = self.cmake_build_dir()
        jobs = os.environ.get("TWINCAL_PIP_JOBS", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", str(build_dir), "--target", ext.target,
                        "--parallel", jobs], check=True)
        module_name = "_twincal" + sysconfig.get_config_var("EXT_SUFFIX")
        built = build_dir / "python" / "twincal" / module_name
        if not built.is_file():
            found = sorted(p.name for p in built.parent.glob("_twincal*"))
            raise RuntimeError(f"extension: value is {built}, not built (found: "
                               f"{found or 'nothing'}); rule: the build directory's Python must "
                               f"be the one running pip ({sys.executable}, module suffix "
                               f"{module_name[8:]})")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)

    def cmake_build_dir(self):
        reused = os.environ.get("TWINCAL_CMAKE_BUILD_DIR")
        if reused:
            build_dir = Path(reused)
            if not build_dir.is_absolute():
                raise RuntimeError(f"TWINCAL_CMAKE_BUILD_DIR: value is {reused}; rule: must be "
                                   "an absolute path (pip runs this script from a directory of "
                                   "its choice)")
            if not (build_dir / "CMakeCache.txt").is_file():
                raise RuntimeError(f"TWINCAL_CMAKE_BUILD_DIR: value is {build_dir}; rule: must be "
                                   "a configured CMake build directory (it has no "
                                   "CMakeCache.txt)")
            source = cache_value(build_dir, "CMAKE_HOME_DIRECTORY")
            if source is None or Path(source).resolve() != SOURCE_DIR:
                raise RuntimeError(f"TWINCAL_CMAKE_BUILD_DIR: value is {build_dir}, a build of "
                                   f"{source}; rule: must build this checkout ({SOURCE_DIR})")
            return build_dir
        build_dir = PACKAGE_DIR / "build" / "cmake"
        options = [
            "-DCMAKE_BUILD_TYPE=Release",
            f"-DTWINCAL_PYTHON={sys.executable}",
            "-DTWINCAL_BUILD_TESTS=OFF",
            "-DTWINCAL_BUILD_BENCHMARKS=OFF",
            "-DTWINCAL_BUILD_EXAMPLES=OFF",
            "-DTWINCAL_BUILD_APPS=ON",  # the experiments library that the bindings link
            "-DTWINCAL_BUILD_PYTHON=ON",
        ]
        if "CMAKE_GENERATOR" not in os.environ and shutil.which("ninja"):
            options.append("-GNinja")
        if "CXX" not in os.environ and shutil.which("clang++-14"):
            options.append("-DCMAKE_CXX_COMPILER=clang++-14")
        if shutil.which("ccache"):
            options.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        subprocess.run(["cmake", "-S", str(SOURCE_DIR), "-B", str(build_dir), *options],
                       check=True)
        return build_dir


setup(
    version=project_version(),
    ext_modules=[CMakeExtension("twincal._twincal", target="twincal_python")],
    cmdclass={"build_ext": CMakeBuild},
)
