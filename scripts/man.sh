#!/usr/bin/env bash
# scripts/man.sh VGPU_RT HELP2MAN OUT: writes the man page OUT.gz (section 1) from the program's
# own --help and --version with Debian's help2man, adding a COMMANDS section with each
# subcommand's --help (the subcommands read from the top-level --help) and an ENVIRONMENT and
# FILES section. cmake/install.cmake runs it after every build of vgpu-rt.
set -euo pipefail
bin=$1 help2man=$2 out=$3
mkdir -p "$(dirname "$out")"
include=$(mktemp)
trap 'rm -f "$include"' EXIT
# roff: a line starting with '.' or "'" is a request, and '\' an escape.
quote() { sed -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"; }
commands=$("$bin" --help | awk '/^Subcommands:/ {on = 1; next} on && /^  [a-z]/ {print $1}')
[ -n "$commands" ] || { echo "man.sh: no subcommands found in $bin --help" >&2; exit 1; }
{
  echo "[COMMANDS]"
  for c in $commands; do
    echo ".SS \"vgpu-rt $c\""
    echo ".nf"
    # CLI11 names the program by the path it was started with: the page names it vgpu-rt.
    "$bin" "$c" --help | sed "s|$bin|vgpu-rt|g" | quote
    echo ".fi"
  done
  echo "[ENVIRONMENT]"
  echo ".TP"
  echo ".B VGPU_RT_SCENES"
  echo "A folder of glTF scenes to use as the bundled ones (render NAME, vgpu-rt scenes)."
  echo "[FILES]"
  echo ".TP"
  echo ".I /usr/share/vgpu-rt/scenes/"
  echo "The bundled scenes (under the install prefix; found relative to the executable)."
  echo ".TP"
  echo ".I /usr/lib/vgpu-rt/libvgpu-image.so"
  echo "The image module (OpenImageIO), loaded on the first image written or compared."
} >"$include"
"$help2man" --no-info --no-discard-stderr --section 1 \
  --name "a virtual 2004 GPU and the stream ray tracer of Fal, Vasconcelos & Delrieux" \
  --include "$include" --output "$out" "$bin"
gzip -9nf "$out"
