"""Builds the abcube extension module with CMake for pip (pyproject.toml).

The module is the CMake target abcube_python; this script configures the project with its
tests and benchmarks off, builds that one target for the interpreter running pip, and puts
the module where setuptools packs it. ABCUBE_CMAKE_BUILD_DIR=DIR reuses a build folder
configured already (the module is then rebuilt there if stale, for DIR's interpreter).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(abcube VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        reuse = os.environ.get("ABCUBE_CMAKE_BUILD_DIR")
        build = Path(reuse).resolve() if reuse else Path(self.build_temp).resolve() / "cmake"
        if not reuse:
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), *generator,
                            "-DCMAKE_BUILD_TYPE=Release", "-DABCUBE_BUILD_TESTS=OFF",
                            "-DABCUBE_BUILD_BENCH=OFF", f"-DABCUBE_PYTHON={sys.executable}"],
                           check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "abcube_python", "abcube_oiio"], check=True)
        built = sorted((build / "python").glob("abcube*.so"))
        if not built:
            raise RuntimeError(f"no abcube module in {build / 'python'} (is pybind11-dev installed?)")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[-1], target)
        # The image module (OpenImageIO's formats and texture filtering), loaded by the
        # extension from beside itself on first need.
        shutil.copy2(build / "libabcube_oiio.so", target.parent / "libabcube_oiio.so")


setup(version=project_version(), ext_modules=[CMakeExtension("abcube")], cmdclass={"build_ext": CMakeBuild})
