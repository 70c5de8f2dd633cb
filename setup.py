"""The CMake build step of `pip install .` (pyproject.toml): builds the extension _vgpu_rt and
the image module for the interpreter running pip, and puts them, the package's Python files
and the bundled scenes into the wheel. The package then finds its scenes and image module
beside itself (host/common/install_paths.h).

VGPU_RT_CMAKE_BUILD=DIR uses a configured build folder instead of a fresh one (CI: the one the
README's command built), provided its Python has this interpreter's version."""

import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE = os.path.dirname(os.path.abspath(__file__))


def built_for(build):
    """(python_version, python_executable) of a build folder's extension, from the
    _build_info.py the build writes beside it, or None."""
    info = {}
    try:
        with open(os.path.join(build, "python", "vgpu_rt", "_build_info.py"), encoding="utf-8") as f:
            exec(f.read(), info)  # noqa: S102 (the build's own file: a few assignments)
    except OSError:
        return None
    return info.get("python_version"), info.get("python_executable")


class CMakeBuild(build_ext):
    def run(self):
        ext = self.extensions[0]
        build = os.environ.get("VGPU_RT_CMAKE_BUILD")
        if build:
            build = os.path.abspath(build)
            found = built_for(build)
            if not found:
                sys.exit("setup.py: %s: not a vgpu-rt build folder with the Python module (no "
                         "python/vgpu_rt/_build_info.py)" % build)
            version, theirs = found
            if version != "%d.%d" % sys.version_info[:2]:
                sys.exit("setup.py: %s was configured for Python %s (%s); this is Python %d.%d: "
                         "unset VGPU_RT_CMAKE_BUILD to build for this interpreter"
                         % (build, version, theirs, *sys.version_info[:2]))
        else:
            build = os.path.join(os.path.abspath(self.build_temp), "cmake")
            subprocess.run(
                ["cmake", "-S", SOURCE, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                 "-DBUILD_TESTING=OFF", "-DVGPU_BENCH=OFF", "-DVGPU_PYTHON=ON",
                 "-DPython_EXECUTABLE=" + sys.executable], check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", build, "--target", "_vgpu_rt", "vgpu-image",
                        "-j", jobs], check=True)

        package = os.path.dirname(self.get_ext_fullpath(ext.name))
        os.makedirs(package, exist_ok=True)
        built = glob.glob(os.path.join(build, "python", "vgpu_rt", "_vgpu_rt*.so"))
        if len(built) != 1:
            sys.exit("setup.py: expected one _vgpu_rt*.so in %s/python/vgpu_rt, found %d"
                     % (build, len(built)))
        shutil.copyfile(built[0], self.get_ext_fullpath(ext.name))
        shutil.copyfile(os.path.join(build, "lib", "vgpu-rt", "libvgpu-image.so"),
                        os.path.join(package, "libvgpu-image.so"))
        # What the extension was built for: this interpreter (the build folder's file may name
        # another executable of the same version).
        with open(os.path.join(build, "python", "vgpu_rt", "_build_info.py"),
                  encoding="utf-8") as f:
            info = f.read()
        info = re.sub(r'^python_executable = ".*"$',
                      'python_executable = "%s"' % sys.executable.replace("\\", "/"), info,
                      flags=re.M)
        with open(os.path.join(package, "_build_info.py"), "w", encoding="utf-8") as f:
            f.write(info)
        scenes = os.path.join(package, "scenes")
        shutil.rmtree(scenes, ignore_errors=True)
        shutil.copytree(os.path.join(SOURCE, "scenes"), scenes)


setup(
    packages=["vgpu_rt"],
    package_dir={"vgpu_rt": "python/vgpu_rt"},
    package_data={"vgpu_rt": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("vgpu_rt._vgpu_rt", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build/pip"}},
    zip_safe=False,
)
