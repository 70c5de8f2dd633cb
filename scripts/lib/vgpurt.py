"""Runs vgpu-rt from a script and reads what it writes: the one place the scripts build a
`vgpu-rt render` command line and load its --stats-json (the contract: docs/cli.md, "Contracts").

A script in scripts/<kind>/ finds this folder with
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
    import vgpurt

    stats = vgpurt.render(exe, "bunny", ["--size", "64x64"], stats_json="bunny.json")

render() runs `EXE render SCENE OPTIONS... [--out F] [--aov K=F...] --stats none --stats-json J -q`
and returns the JSON as a dict. A refused option or a failed render raises Failed, which carries
vgpu-rt's last line on stderr (the one line a refusal prints) and its exit status (2 for a refusal).
"""
import json
import os
import re
import subprocess
import sys


class Failed(RuntimeError):
    """vgpu-rt exited with a non-zero status: `message` is its last line on stderr."""

    def __init__(self, cmd, returncode, message):
        super().__init__(f"{' '.join(cmd)}: exit {returncode}: {message}")
        self.cmd, self.returncode, self.message = cmd, returncode, message


def render_command(exe, scene, opts=(), *, stats_json=None, out=None, aovs=None, quiet=True):
    """The command line render() runs; `aovs` maps an AOV name (depth, hit) to its EXR file."""
    cmd = [exe, "render", str(scene), *opts]
    if out:
        cmd += ["--out", out]
    if aovs:
        cmd += ["--aov", *[f"{k}={v}" for k, v in aovs.items()]]
    cmd += ["--stats", "none"]  # no table on stdout: a script reads the JSON
    if stats_json:
        cmd += ["--stats-json", stats_json]
    if quiet:
        cmd += ["-q"]
    return cmd


def run(cmd, *, timeout=None, cwd=None, echo=False):
    """Runs any vgpu-rt (or bench) command; its stdout is returned, stderr kept for Failed."""
    if echo:
        print("+", " ".join(cmd), file=sys.stderr, flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=cwd)
    if p.returncode != 0:
        lines = (p.stderr.strip() or p.stdout.strip()).splitlines()
        raise Failed(cmd, p.returncode, lines[-1] if lines else f"exit {p.returncode}")
    return p.stdout


def render(exe, scene, opts=(), *, stats_json, out=None, aovs=None, timeout=None, cwd=None,
           echo=False):
    """Renders SCENE (a bundled name or a glTF path) and returns its --stats-json as a dict."""
    run(render_command(exe, scene, opts, stats_json=stats_json, out=out, aovs=aovs),
        timeout=timeout, cwd=cwd, echo=echo)
    return read_stats(stats_json)


def read_stats(path):
    """A --stats-json file (one frame, or {frames: [...]} for --frames) as a dict."""
    with open(path) as f:
        return json.load(f)


def compare(exe, a, b, threshold=None):
    """`vgpu-rt compare A B`: (share of differing pixels 0..1, PSNR or inf, max difference or
    None, its text). Raises Failed when the images cannot be compared."""
    cmd = [exe, "compare", a, b] + (["--threshold", str(threshold)] if threshold is not None else [])
    p = subprocess.run(cmd, capture_output=True, text=True)
    text = p.stdout + p.stderr
    share = re.search(r"([0-9.eE+-]+)% of pixels differ", text)
    if not share:
        raise Failed(cmd, p.returncode, f"cannot read compare's output: {text!r}")
    psnr = re.search(r"PSNR ([0-9.eE+-]+|inf)", text)
    most = re.search(r"max ([0-9.eE+-]+)", text)
    return (float(share.group(1)) / 100.0, float(psnr.group(1)) if psnr else float("inf"),
            float(most.group(1)) if most else None, text)


def kernel_names(exe):
    """The kernels `vgpu-rt kernels` lists (its table's first column)."""
    out = run([exe, "kernels"])
    return [line.split()[0] for line in out.splitlines()[1:]
            if line.strip() and not line.startswith("instructions:")]


def uneven_scenes(folder):
    """Writes docs/studies/structures.md's uneven scenes (scripts/scenes/uneven_scenes.py) into folder and
    returns their paths by name: {"stadium": ..., "scales": ...}."""
    here = os.path.dirname(os.path.abspath(__file__))
    run([sys.executable, os.path.join(here, "..", "scenes", "uneven_scenes.py"), folder])
    return {name: os.path.join(folder, name + ".gltf") for name in ("stadium", "scales")}
