"""vgpu-rt from Python: the virtual 2004 GPU and the stream ray tracer, frame by frame.

    import vgpu_rt
    frame = vgpu_rt.render("bunny", size="64x64", profile="gf6600")
    frame.image        # (64, 64, 3) float32, linear RGB, row 0 at the top
    frame.depth        # (64, 64) distance to the primary hit, 0 where the ray misses
    frame.hit          # (64, 64) the primary hit's input triangle id, -1 where it misses
    frame.stats        # the dict `vgpu-rt render --stats-json` writes
    vgpu_rt.predict(frame.stats, "gf5700")   # the cost model's breakdown, in ms

Kernels of your own: @vgpu_rt.kernel(units=[...], outputs=1, uniforms={...}) records a Python
function over lane values into the vgpu's program form; Device.run runs, counts and checks it
against the card's rules as the project's kernels (vgpu_rt.KernelError: one line). See kernel().

render() takes the command line's render options under the same names, '-' written '_'
(texture_filter="bilinear", spp=4, aa="adaptive", time=0.5, ...) and with its defaults, with
two exceptions: `stats` defaults to "none" (the statistics come back as frame.stats) and `quiet`
to True (no progress lines on stderr). Bad values raise ValueError with the command line's
message; a scene that is neither a bundled name nor a file raises FileNotFoundError.

The extension (_vgpu_rt) is built for one Python interpreter: by `pip install .` for the one
running pip, by the project's CMake (into build/python/vgpu_rt/, and `cmake --install` from
there) for Debian's /usr/bin/python3 unless -DPython_EXECUTABLE names another. Imported by
another Python version, or without NumPy, the import raises one ImportError that names both
interpreters and the fix. From a source tree (the repository root's vgpu_rt link to
python/vgpu_rt) the package loads the build folder's extension.
"""

import glob as _glob
import importlib.util as _importlib_util
import json as _json
import os as _os
import sys as _sys


def _load_module(name, path):
    spec = _importlib_util.spec_from_file_location(__name__ + "." + name, path)
    module = _importlib_util.module_from_spec(spec)
    spec.loader.exec_module(module)
    _sys.modules[__name__ + "." + name] = module
    return module


def _extension_folder():
    """The folder holding the extension _vgpu_rt: this package's own (an installed package, or
    the build folder's build/python/vgpu_rt), else, imported from a source tree (the repository
    root's vgpu_rt link to python/vgpu_rt), that tree's build folder ($VGPU_RT_BUILD or build)."""
    here = _os.path.dirname(_os.path.realpath(__file__))
    candidates = [here]
    root = _os.path.dirname(_os.path.dirname(here))  # python/vgpu_rt -> the repository
    if _os.path.isfile(_os.path.join(root, "CMakeLists.txt")) and _os.path.isfile(
            _os.path.join(root, "VERSION")):
        build = _os.environ.get("VGPU_RT_BUILD") or _os.path.join(root, "build")
        candidates.append(_os.path.join(build, "python", "vgpu_rt"))
    for folder in candidates:
        if _glob.glob(_os.path.join(folder, "_vgpu_rt*.so")):
            return folder
    raise ImportError(
        "vgpu_rt: the extension _vgpu_rt is not built; build it with `cmake -S . -B build -G Ninja "
        "&& cmake --build build --target _vgpu_rt`, or install the package with "
        "`python3 -m pip install --no-build-isolation .` (looked in " + ", ".join(candidates) + ")")


def _running():
    return "%s (Python %s)" % (_sys.executable or "python", _sys.version.split()[0])


def _check_interpreter(info):
    """One ImportError, naming the running interpreter, the one the extension was built for and
    the fix, where the extension cannot work here: another Python version, or no NumPy."""
    built_for = "%s (Python %s)" % (info.python_executable, info.python_full_version)
    rebuild = ("or build vgpu_rt for this interpreter: `%s -m pip install --no-build-isolation "
               "<vgpu-rt source folder>`" % (_sys.executable or "python"))
    if "%d.%d" % _sys.version_info[:2] != info.python_version:
        raise ImportError(
            "vgpu_rt %s was built for %s and cannot be loaded by %s: run it with %s, %s"
            % (info.version, built_for, _running(), info.python_executable, rebuild))
    try:
        import numpy  # noqa: F401  (the extension's arrays are NumPy arrays)
    except ImportError:
        raise ImportError(
            "vgpu_rt %s needs NumPy, which %s cannot import (it was built for %s): run it with "
            "that interpreter, install NumPy for this one (`%s -m pip install numpy`, or a "
            "virtual environment made with --system-site-packages over Debian's python3-numpy), "
            "%s" % (info.version, _running(), built_for, _sys.executable or "python", rebuild)
        ) from None


def _load_extension():
    folder = _extension_folder()
    info_path = _os.path.join(folder, "_build_info.py")
    if not _os.path.isfile(info_path):
        raise ImportError("vgpu_rt: %s is missing (the build writes it beside the extension; "
                          "rebuild or reinstall vgpu_rt)" % info_path)
    info = _load_module("_build_info", info_path)
    _check_interpreter(info)
    return _load_module("_vgpu_rt", sorted(_glob.glob(_os.path.join(folder, "_vgpu_rt*.so")))[0])


_ext = _load_extension()

#: vgpu-rt's version (the repository's VERSION file), as `vgpu-rt --version` prints it.
__version__ = _ext.version()

FrameStats = _ext.FrameStats
Texture = _ext.Texture
Kernel = _ext.Kernel
#: Every kernel (fragment program) by name, in kernels/registry.h's order, with its default
#: uniforms: vgpu_rt.kernels["traversal"].units lists what each texture unit holds.
kernels = _ext.kernels()

# The command line's render options: name -> (default, description, is_flag).
_OPTIONS = {name: (default, text, flag) for name, default, text, flag in _ext.render_options()}
# Where Python's default differs from the command line's (see the module's docstring).
_PYTHON_DEFAULTS = {"stats": "none", "quiet": True}
_ON_OFF = {"shadows", "masks", "mrt"}  # options taking on|off, which also take True/False


class Stats(dict):
    """The dict `--stats-json` writes, holding the frame's C++ statistics as `frame_stats`,
    which predict() prices as the command line does (without reading the dict back)."""

    def __init__(self, data, frame_stats=None):
        super().__init__(data)
        self.frame_stats = frame_stats


class Frame:
    """One rendered frame: image (H, W, 3), depth (H, W), hit (H, W) as float32 NumPy arrays
    (no copies: each owns the library's buffer) and stats, the --stats-json dict (Stats)."""

    __slots__ = ("image", "depth", "hit", "stats")

    def __init__(self, image, depth, hit, stats):
        self.image, self.depth, self.hit, self.stats = image, depth, hit, stats

    def __repr__(self):
        h, w = self.image.shape[:2]
        return f"<vgpu_rt.Frame {w}x{h} {self.stats.get('scene', '')!r}>"


def _word(name, value):
    """One option's value as the command line's word."""
    if isinstance(value, bool) and name in _ON_OFF:
        return "on" if value else "off"
    if isinstance(value, (tuple, list)) and name in ("size", "trace_pixel"):
        if len(value) != 2:
            raise ValueError(f"{name}: expected two numbers, got {value!r}")
        return ("{}x{}" if name == "size" else "{},{}").format(*value)
    if isinstance(value, (tuple, list)) and name == "aa_budget":
        return ",".join(str(v) for v in value)  # percentages per level, e.g. (30, 28)
    return str(value)


def _arguments(scene, options):
    """render()'s arguments as the command line's: [scene, --option, value, ...]."""
    if not isinstance(scene, (str, _os.PathLike)):
        raise TypeError(f"render(): scene must be a name or a path, not {type(scene).__name__}")
    args = [_os.fspath(scene)]
    given = dict(_PYTHON_DEFAULTS)
    given.update(options)
    for key, value in given.items():
        name = key.replace("_", "-")
        if name not in _OPTIONS:
            raise TypeError(f"render() got an unexpected keyword argument '{key}'")
        if value is None:
            continue
        flag = _OPTIONS[name][2]
        if flag:
            if value:
                args.append("--" + name)
            continue
        values = value if name == "aov" and isinstance(value, (list, tuple)) else [value]
        for v in values:
            args += ["--" + name, _word(key, v)]
    return args


def render(scene="bunny", **options):
    """Renders `scene` (a name from scenes() or a .gltf/.glb path) as `vgpu-rt render` does.

    Options are the command line's, '-' written '_', e.g. size="128x128" (or (128, 128)),
    bounces=2, spp=4, aa="adaptive", profile="gf6600", accel="bvh", masks=True, time=0.5,
    out="frame.png", stats_json="frame.json". Defaults are the command line's except stats
    ("none") and quiet (True). Returns a Frame; with frames="A:B:N" (several frames) the
    arrays are the last frame's and stats holds every frame, as --stats-json writes them.
    Raises ValueError for a bad value or combination, FileNotFoundError for a missing scene.

    shader=K, camera=K: kernels of your own (@vgpu_rt.kernel(stage="shader") or "camera", see
    stages()) in place of the project's shading pass and primary rays, on the stream and gl
    engines, counted under their own names (frame.stats["user_kernels"]).
    """
    image, depth, hit, text, frame_stats = _ext.render(*_render_call(scene, options))
    return Frame(image, depth, hit, Stats(_json.loads(text), frame_stats))


def _render_call(scene, options):
    """The extension's arguments for render() and passes(): the command line's, then the
    kernels of your own for the shader and camera stages (None where not given)."""
    options = dict(options)
    shader, camera = options.pop("shader", None), options.pop("camera", None)
    args = _arguments(scene, options)
    return (args, _stage_kernel("shader", shader, options),
            _stage_kernel("camera", camera, options))


def _stage_kernel(stage, k, options):
    """A kernel of your own for `stage` as the extension takes it: (a fresh recording with its
    default uniforms, its units), after the card's rules on the frame's profile; None: none."""
    if k is None:
        return None
    if not isinstance(k, UserKernel):
        raise TypeError(f"render(): {stage}= takes a @vgpu_rt.kernel(stage=\"{stage}\") "
                        f"function, not {type(k).__name__}")
    if k.stage is not None and k.stage != stage:
        raise KernelError(f"kernel '{k.name}' was written for the {k.stage} stage, not the "
                          f"{stage} stage")
    profile = options.get("profile", _OPTIONS["profile"][0])
    if isinstance(profile, str):
        k.check(profile)
    try:
        return (k._record(k.uniforms), k.units)  # its own: the frame sets its uniforms
    except ValueError as e:
        raise KernelError(_one_line(e)) from None


def _option_lines():
    lines = []
    for name, (default, text, flag) in _OPTIONS.items():
        shown = _PYTHON_DEFAULTS.get(name, "False" if flag else default)
        lines.append(f"    {name.replace('-', '_')}: {text}" + (f" (default {shown})" if shown != "" else ""))
    return "\n".join(lines)


render.__doc__ += "\n    Options (from the command line's --help):\n" + _option_lines() + "\n"


class Pass:
    """One pass of a frame, as passes() shows it: its index (from 0), kernel and paper_name,
    iteration (from 1) and trace (primary, shadow or reflected; None outside a trace), counters (the pass's own),
    frame_totals (the frame so far), query (the fragments its occlusion query counted, or None
    when it ran without one), target_name and target, the render target's texels after the pass
    as a (height, width, channels) float32 array (a copy: later passes rewrite the texture).

    The per-pixel state, as (height, width) arrays over the target (copies), as the HTML report
    shows it: work (bool), the pixels whose fragments had work in the pass, the stencil it ran
    under (None when it ran without one: every fragment ran); written (bool), the pixels a
    counting pass's occlusion query counted (None for other passes); iterations (uint32), the
    loop iterations each fragment of a looping pass ran (None without a loop)."""

    __slots__ = ("index", "kernel", "paper_name", "iteration", "trace", "counters",
                 "frame_totals", "query", "target_name", "target", "work", "written",
                 "iterations")

    def __init__(self, fields):
        for key in self.__slots__:
            setattr(self, key, fields[key])

    def __repr__(self):
        q = "" if self.query is None else f", query {self.query}"
        return (f"<vgpu_rt.Pass {self.index} {self.kernel} -> {self.target_name}, "
                f"iteration {self.iteration} {self.trace}{q}>")


class Passes:
    """A frame rendered pass by pass (see passes()). The render runs on a worker thread that
    stops after each pass until the next one is asked for: stop iterating to stop the frame
    there, iterate again to resume it. Once every pass was seen, `frame` is the Frame."""

    def __init__(self, scene="bunny", **options):
        self._stepper = _ext.PassStepper(*_render_call(scene, options))
        # The first pass, fetched now so that options the frame refuses raise here.
        self._first = self._stepper.next()

    def __iter__(self):
        return self

    def __next__(self):
        if self._first is not None:
            fields, self._first = self._first, None
        else:
            fields = self._stepper.next()
        if fields is None:
            raise StopIteration
        return Pass(fields)

    @property
    def frame(self):
        """The frame as render() returns it, once every pass was seen; else None."""
        result = self._stepper.result()
        if result is None:
            return None
        image, depth, hit, text, frame_stats = result
        return Frame(image, depth, hit, Stats(_json.loads(text), frame_stats))


def passes(scene="bunny", **options):
    """Renders `scene` with render()'s options, stopping after each pass: returns an iterator
    of Pass objects (the tracer's pass observer, as the HTML report sees the frame).

        steps = vgpu_rt.passes("bunny", size="32x32")
        for p in steps:
            if p.query is not None:
                print(p.index, p.kernel, p.query)   # the counts that steer the host
        steps.frame.image

    One frame only (not frames=...), on the stream engine, without report or stats_csv.
    """
    return Passes(scene, **options)


def scenes():
    """The bundled scenes as a dict: name -> path of its glTF file."""
    return dict(_ext.scenes())


def scenes_dir():
    """The folder the bundled scenes were found in (an installed tree's share/vgpu-rt/scenes,
    the pip-installed package's scenes/, or $VGPU_RT_SCENES), or "" where none was found."""
    return _ext.scenes_dir()


def profiles():
    """The built-in hardware profiles (gf5700, r300, gf6600, rtx4090, h200, h100), each a dict of
    its main figures: name, display, core_mhz, mem_gbps, bus_mbps, max_outputs,
    max_loop_iterations, and what the cost model prices with: pipelines, alu_lanes, alu_per_clock,
    fp32_rate, texels_per_clock, pass_us, program_load_us, readback_us, dynamic_branching and
    branch_granularity (fragments that branch together)."""
    return _ext.profiles()


def predict(stats, profile):
    """The cost model's prediction of a frame on `profile`, in ms, by where it goes (the keys
    of --stats-json's predicted_breakdown, plus total_ms).

    `stats` is a Frame, its Stats, or a plain --stats-json dict (e.g. json.load of a file the
    command line wrote). Either gives the command line's figure: a render keeps each kernel's
    totals (not every pass), and the model prices those, which the dict holds too.
    """
    if isinstance(stats, Frame):
        stats = stats.stats
    if isinstance(stats, Stats) and stats.frame_stats is not None:
        return _ext.predict(stats.frame_stats, profile)
    if isinstance(stats, dict):
        return _ext.predict_json(_json.dumps(stats), profile)
    raise TypeError(f"predict(): stats must be a Frame or a --stats-json dict, not {type(stats).__name__}")


# ------------------------------------------------------------------------------------------------
# Kernels written in Python (issue 48): the recorder, in _kernels.py.
from ._kernels import (KernelError, UserKernel, Fragments, Lanes, Mask, Vec4, Stage, kernel,
                       select, floor, sqrt, rsqrt, stages, _one_line)


class Device(_ext.Device):
    """The virtual GPU with a hardware profile's limits and counters."""

    @property
    def stats(self):
        """Every pass this device ran, per kernel and in total, under --stats-json's keys
        ("totals", "kernels"): vgpu_rt.predict(dev.stats, "gf5700") prices them."""
        return Stats(_json.loads(self._stats_json()), self._frame_stats())

    def run(self, kernel, units, targets, query=False, uniforms=None):
        """One pass of `kernel` (vgpu_rt.kernels[...] or a @vgpu_rt.kernel function) over the
        whole of targets[0] (its outputs' targets), units[i] bound to texture unit i. Returns
        the pass's counters and, with query=True, the fragments an occlusion query counted
        (else None). A Python kernel is recorded with `uniforms` over its defaults and checked
        against the card's rules first (KernelError, one line)."""
        if isinstance(kernel, UserKernel):
            kernel.check(self.profile, uniforms)
            self._program = kernel.recorded(uniforms)  # lives as long as the device uses it
            return self._run_recorded(self._program, units, targets, query)
        if uniforms:
            raise TypeError("run(): uniforms= is for kernels written in Python")
        return super().run(kernel, units, targets, query)


__all__ = ["stages", "Stage", "render", "passes", "scenes", "profiles", "predict", "kernels", "Device", "Texture",
           "Kernel", "Frame", "Stats", "FrameStats", "Pass", "Passes", "kernel", "UserKernel",
           "KernelError", "Fragments", "Lanes", "Mask", "Vec4", "select", "floor", "sqrt",
           "rsqrt"]
