"""Builds qem._qem with the repository's CMake (the library, then the pybind11 module target) and
puts it in the wheel: the small build step scikit-build would otherwise do. Settings: CMAKE_ARGS
(extra arguments), QEM_BUILD_JOBS (default 2)."""
import os
import pathlib
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build_dir = pathlib.Path(self.build_temp).resolve() / "cmake"
        build_dir.mkdir(parents=True, exist_ok=True)
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
            "-DQEM_BUILD_PYTHON=ON", "-DQEM_BUILD_TESTS=OFF", f"-DPython3_EXECUTABLE={sys.executable}",
        ] + shlex.split(os.environ.get("CMAKE_ARGS", ""))
        subprocess.run(configure, check=True)
        jobs = os.environ.get("QEM_BUILD_JOBS", "2")
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "qem_python", "-j", jobs], check=True)
        built = next((build_dir / "python" / "qem").glob("_qem*.so"))
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    ext_modules=[Extension("qem._qem", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' default build/ is CMake's build tree in this repository: keep out of it.
    options={"build": {"build_base": "build-pip"}},
)
