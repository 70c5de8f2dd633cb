"""import vgpu_rt where the extension cannot work: another Python version than it was built for,
or no NumPy. Each is one ImportError, raised by the import itself (not the first render), that
names the running interpreter, the one the extension was built for, and the fix."""

import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import vgpu_rt


def package_copy(folder, python_version=None):
    """A copy of the package in folder/vgpu_rt (its _build_info.py saying `python_version`)."""
    here = os.path.dirname(vgpu_rt.__file__)
    dest = os.path.join(folder, "vgpu_rt")
    os.makedirs(dest)
    shutil.copy(os.path.join(here, "__init__.py"), dest)
    for ext in glob.glob(os.path.join(here, "_vgpu_rt*.so")):
        shutil.copy(ext, dest)
    with open(os.path.join(here, "_build_info.py"), encoding="utf-8") as f:
        info = f.read()
    if python_version:
        info = re.sub(r'^python_version = ".*"$', 'python_version = "%s"' % python_version, info,
                      flags=re.M)
        info = re.sub(r'^python_full_version = ".*"$',
                      'python_full_version = "%s.9"' % python_version, info, flags=re.M)
    with open(os.path.join(dest, "_build_info.py"), "w", encoding="utf-8") as f:
        f.write(info)


def import_error(folder, prelude=""):
    """The last line of stderr of `import vgpu_rt` from folder, in a fresh interpreter."""
    env = dict(os.environ, PYTHONPATH=folder)
    r = subprocess.run([sys.executable, "-c", prelude + "import vgpu_rt"], env=env,
                       capture_output=True, text=True, cwd=folder)
    return r.returncode, r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""


class ImportTest(unittest.TestCase):
    def test_the_version_is_the_version_files(self):
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        with open(os.path.join(root, "VERSION"), encoding="utf-8") as f:
            self.assertEqual(vgpu_rt.__version__, f.read().strip())

    def test_another_python_version_is_one_import_error_naming_both_and_the_fix(self):
        with tempfile.TemporaryDirectory() as folder:
            package_copy(folder, python_version="2.7")
            code, line = import_error(folder)
        self.assertNotEqual(code, 0)
        running = "%s (Python %s)" % (sys.executable, sys.version.split()[0])
        self.assertTrue(line.startswith("ImportError: vgpu_rt %s was built for " % vgpu_rt.__version__), line)
        self.assertIn("(Python 2.7.9) and cannot be loaded by " + running, line)
        self.assertIn("-m pip install --no-build-isolation <vgpu-rt source folder>", line)

    def test_no_numpy_is_one_import_error_naming_both_and_the_fix(self):
        with tempfile.TemporaryDirectory() as folder:
            package_copy(folder)
            # numpy as an interpreter without it sees it: importing it fails.
            code, line = import_error(folder, "import sys; sys.modules['numpy'] = None; ")
        self.assertNotEqual(code, 0)
        self.assertTrue(line.startswith(
            "ImportError: vgpu_rt %s needs NumPy, which %s (Python %s) cannot import"
            % (vgpu_rt.__version__, sys.executable, sys.version.split()[0])), line)
        self.assertIn("it was built for ", line)
        self.assertIn("-m pip install numpy", line)

    def test_the_built_package_finds_its_scenes_beside_itself(self):
        self.assertTrue(os.path.isfile(os.path.join(vgpu_rt.scenes_dir(), "bunny.gltf")))
        self.assertIn("bunny", vgpu_rt.scenes())


if __name__ == "__main__":
    unittest.main()
