"""Build the compiled module with CMake when installing with pip (offline, no isolation)."""

import os
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        out = Path(self.get_ext_fullpath(ext.name)).resolve().parent
        build = Path(self.build_temp).resolve()
        build.mkdir(parents=True, exist_ok=True)
        src = Path(__file__).resolve().parent
        subprocess.check_call(
            ["cmake", "-S", str(src), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
             f"-DPython3_EXECUTABLE={sys.executable}", f"-DCONTACT_PYTHON_OUTPUT_DIR={out}",
             "-DCONTACT_BUILD_TESTS=OFF", "-DCONTACT_BUILD_BENCHMARKS=OFF"])
        subprocess.check_call(["cmake", "--build", str(build), "--target", "_cpp", "-j",
                               str(os.cpu_count() or 2)])


setup(ext_modules=[CMakeExtension("dolfinx_forms._cpp")], cmdclass={"build_ext": CMakeBuild})
