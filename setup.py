"""Builds the abcube extension module with CMake for pip (pyproject.toml).

The module is the CMake target abcube_python. A build folder the tree already has (build/,
configured by the README's commands) is reused when its module is for this interpreter's
ABI (the file name's suffix, cpython-311-x86_64-linux-gnu on Debian 12): only that target
and the image module are built there, in seconds when they are current. Otherwise a fresh
build folder is configured with the tests and benchmarks off, for the interpreter running
pip. ABCUBE_CMAKE_BUILD_DIR=DIR reuses DIR instead; ABCUBE_CMAKE_BUILD_DIR=new builds
afresh. pip shows the build's own output with -v.
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

ROOT = Path(__file__).resolve().parent


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(abcube VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


def reusable_build():
    """The tree's build/ when its module is for this interpreter, else None."""
    build = ROOT / "build"
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    if not (build / "CMakeCache.txt").exists():
        return None
    cache = (build / "CMakeCache.txt").read_text(errors="replace")
    python = re.search(r"^ABCUBE_PYTHON:\w+=(.*)$", cache, re.M)
    if not python or not Path(python.group(1)).exists():
        return None
    built_for = subprocess.run([python.group(1), "-c", "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))"],
                               capture_output=True, text=True).stdout.strip()
    return build if built_for == suffix else None


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        reuse = os.environ.get("ABCUBE_CMAKE_BUILD_DIR")
        if reuse == "new":
            reuse = None
        elif not reuse and (found := reusable_build()):
            reuse = str(found)
            print(f"setup.py: reusing the build in {reuse} (ABCUBE_CMAKE_BUILD_DIR=new builds afresh)", flush=True)
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
