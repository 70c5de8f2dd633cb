#!/usr/bin/env bash
# scripts/ci/install.sh [BUILD]: the three ways README's "Install" gives, tried as a user would,
# on a build folder the README's command made (default: build). .ci/run calls it.
#   1. cmake --install into a scratch prefix, which is then moved (the installed tree finds its
#      files relative to itself) while the build folder is moved out of reach: the installed
#      vgpu-rt renders and lists scenes from another folder, the installed Python package
#      renders, examples/own_kernel builds against the package with find_package and passes its
#      test, and no installed file names the source or build folder.
#   2. pip install . into a virtual environment (--system-site-packages, offline, reusing the
#      build folder's objects), imported from another folder; and in a bare environment (no
#      NumPy) the import fails with one ImportError naming both interpreters.
#   3. cpack -G DEB: the two packages' contents and declared dependencies (dpkg-deb).
set -euo pipefail
cd "$(dirname "$0")/../.."
src=$PWD
build=$(realpath "${1:-build}")
scratch=$(mktemp -d /tmp/vgpu-install.XXXXXX)
restore() {
  [ -d "$scratch/build-away" ] && mv "$scratch/build-away" "$build"
  rm -rf "$scratch"
}
trap restore EXIT
fail() { echo "install: FAILED: $*" >&2; exit 1; }
step() { echo "install: $*"; }

# --- 2 (first: pip reuses the build folder, which 1 moves away) ------------------------------
step "pip install . into a virtual environment"
/usr/bin/python3 -m venv --system-site-packages "$scratch/venv"
VGPU_RT_CMAKE_BUILD="$build" "$scratch/venv/bin/python" -m pip install --quiet --no-index \
  --no-build-isolation "$src"
/usr/bin/python3 -m venv --without-pip "$scratch/bare"

# --- 3 -----------------------------------------------------------------------------------------
step "cpack -G DEB"
(cd "$build" && cpack -G DEB >"$scratch/cpack.log" 2>&1) || { cat "$scratch/cpack.log"; fail "cpack"; }
version=$(cat VERSION)
deb="$build/packages/vgpu-rt_${version}_amd64.deb"
dev="$build/packages/vgpu-rt-dev_${version}_amd64.deb"
[ -f "$deb" ] && [ -f "$dev" ] || fail "expected $deb and $dev (got: $(ls "$build/packages"))"
contents=$(dpkg-deb -c "$deb")
devcontents=$(dpkg-deb -c "$dev")
for f in ./usr/bin/vgpu-rt ./usr/lib/vgpu-rt/libvgpu-image.so ./usr/share/vgpu-rt/scenes/bunny.gltf \
  ./usr/share/man/man1/vgpu-rt.1.gz ./usr/lib/python3/dist-packages/vgpu_rt/__init__.py \
  ./usr/lib/python3/dist-packages/vgpu_rt/_build_info.py; do
  grep -q " $f\$" <<<"$contents" || fail "$deb lacks $f"
done
for f in ./usr/include/vgpu_rt/vgpu/gpu.h ./usr/include/vgpu_rt/host/cli/render.h \
  ./usr/lib/libvgpu.a ./usr/lib/cmake/vgpu_rt/vgpu_rtConfig.cmake; do
  grep -q " $f\$" <<<"$devcontents" || fail "$dev lacks $f"
done
depends=$(dpkg-deb -f "$deb" Depends)
for d in libopenimageio2.4 libc6 libstdc++6 python3-numpy "python3 (>= 3."; do
  [[ $depends == *"$d"* ]] || fail "$deb: Depends lacks $d: $depends"
done
devdepends=$(dpkg-deb -f "$dev" Depends)
for d in "vgpu-rt (= $version)" libglm-dev libcli11-dev; do
  [[ $devdepends == *"$d"* ]] || fail "$dev: Depends lacks $d: $devdepends"
done
step "packages: $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB), $(basename "$dev") ($(du -k "$dev" | cut -f1) KiB)"

# --- 1 -----------------------------------------------------------------------------------------
step "cmake --install into a scratch prefix"
cmake --install "$build" --prefix "$scratch/prefix" >/dev/null
# No installed file names the source or build folder (the scenes' path, the image module's,
# a Python loader's fallback...).
if grep -rl --binary-files=text -e "$src" -e "$build" "$scratch/prefix"; then
  fail "the files above name $src or $build"
fi
mv "$scratch/prefix" "$scratch/moved"
mv "$build" "$scratch/build-away"
prefix="$scratch/moved"
mkdir "$scratch/elsewhere"
cd "$scratch/elsewhere"
unset VGPU_RT_SCENES VGPU_RT_BUILD PYTHONPATH
PATH="$prefix/bin:/usr/bin:/bin"
step "the installed vgpu-rt from another folder: $(vgpu-rt --version)"
vgpu-rt scenes | grep -q "^bunny " || fail "vgpu-rt scenes lists no bunny"
vgpu-rt render bunny --size 32x32 --out b.png --quiet >render.txt || fail "vgpu-rt render"
[ -s b.png ] || fail "vgpu-rt render wrote no b.png"
grep -q "passes" render.txt || fail "vgpu-rt render printed no pass statistics"
step "the installed Python package"
PYTHONPATH="$prefix/lib/python3/dist-packages" /usr/bin/python3 -c "
import vgpu_rt, sys
f = vgpu_rt.render('bunny', size='16x16')
assert f.stats['version'] == vgpu_rt.__version__ == '$version', (f.stats['version'], vgpu_rt.__version__)
assert vgpu_rt.scenes_dir().startswith('$prefix/'), vgpu_rt.scenes_dir()
print('install: python', vgpu_rt.__version__, 'from', vgpu_rt.__file__)
" || fail "the installed Python package"
step "examples/own_kernel against the installed package"
cmake -S "$src/examples/own_kernel" -B own -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >own.log ||
  { cat own.log; fail "configuring examples/own_kernel"; }
cmake --build own >>own.log || { cat own.log; fail "building examples/own_kernel"; }
ctest --test-dir own --output-on-failure >>own.log || { cat own.log; fail "examples/own_kernel's test"; }
step "the pip-installed package from another folder"
"$scratch/venv/bin/python" -c "
import vgpu_rt
f = vgpu_rt.render('bunny', size='16x16')
assert f.image.shape == (16, 16, 3)
assert vgpu_rt.scenes_dir().startswith('$scratch/venv/'), vgpu_rt.scenes_dir()
print('install: pip', vgpu_rt.__version__, 'from', vgpu_rt.__file__)
" || fail "the pip-installed package"
site=$("$scratch/venv/bin/python" -c "import vgpu_rt, os; print(os.path.dirname(os.path.dirname(vgpu_rt.__file__)))")
step "an interpreter without NumPy"
if PYTHONPATH="$site" "$scratch/bare/bin/python" -c "import vgpu_rt" 2>err.txt; then
  fail "import vgpu_rt succeeded without NumPy"
fi
tail -1 err.txt
grep -q "^ImportError: vgpu_rt $version needs NumPy, which $scratch/bare/bin/python" err.txt ||
  fail "the import's error is not the one expected"
grep -q "was built for $scratch/venv/bin/python" err.txt || fail "the error does not name the build's interpreter"
step "all three ways work"
