"""Kernels written in Python (issue 48): @vgpu_rt.kernel records a Python function over lane
values into the vgpu's program form. Imported by the package (vgpu_rt.kernel, vgpu_rt.Lanes, ...);
not for importing on its own."""

import inspect as _inspect
import os as _os
import sys as _sys
import traceback as _traceback

from . import _ext

# Kernels written in Python (issue 48). The function runs once, over the lane values below, to
# record it: each operation appends a node to a list as vgpu/record.h's recording lane family
# does (the same node codes, the same prefix Program::record makes, the same folding of masks
# with a constant); one call into the extension turns the list into a vgpu::RecordedProgram,
# which the device runs, counts and checks as it does the project's kernels.

_OPS = {_name: _i for _i, _name in enumerate(_ext.record_ops())}


class KernelError(ValueError):
    """A kernel that cannot be recorded or run: one line, naming the kernel and, where its own
    code is at fault, the file and line (a card's rule it breaks names the rule, the card and
    both numbers, and the built-in profiles it fits)."""


_HERE = _os.path.dirname(_os.path.realpath(__file__))


def _is_ours(filename):
    """Whether filename is one of this package's files (not the kernel's own code)."""
    return _os.path.dirname(_os.path.realpath(filename)) == _HERE


def _user_line():
    """'FILE, line N' of the innermost frame outside this package (the kernel's own code)."""
    frame = _sys._getframe(1)
    while frame is not None and _is_ours(frame.f_code.co_filename):
        frame = frame.f_back
    if frame is None:
        return "?"
    return f"{frame.f_code.co_filename}, line {frame.f_lineno}"


def _one_line(text):
    return " ".join(str(text).split("\n"))


class _Recorder:
    """One recording: the node list, as vgpu::Program::record() starts it (the fragment's
    position, the live and kill masks, each output cleared to four zero constants)."""

    def __init__(self, kernel, uniforms):
        self.kernel, self.uniforms = kernel, uniforms
        self.nodes = []
        self.frag_x = self.push("frag_x")
        self.frag_y = self.push("frag_y")
        self.mask_true = self.push("mask_const", value=1.0)
        self.mask_false = self.push("mask_const", value=0.0)
        self.kill = self.mask_false
        self.outputs = [[self.push("constant") for _ in range(4)] for _ in range(kernel.outputs)]
        self.loop = None  # (begin, mid, end, max_iterations, entry)
        self.uniform_nodes = {}  # name -> the constant nodes reading it (a frame sets them)
        self.in_loop = False

    def push(self, op, a=-1, b=-1, c=-1, unit=-1, value=0.0):
        self.nodes.append((_OPS[op], a, b, c, unit, float(value)))
        return len(self.nodes) - 1

    def fail(self, what):
        raise KernelError(f"kernel '{self.kernel.name}', {_user_line()}: {what}")


def _refuse_truth(r, what):
    r.fail(f"a Python {what} on a lane value cannot be recorded (each fragment has its own "
           "value); choose per fragment with vgpu_rt.select(mask, a, b), f.min/f.max, or "
           "`with f.branch(mask):`")


class _Arithmetic:
    """+ - * / (and their reflected forms) through the subclass's _bin(other, op, swap)."""

    def __add__(self, o): return self._bin(o, "add")
    def __radd__(self, o): return self._bin(o, "add", True)
    def __sub__(self, o): return self._bin(o, "sub")
    def __rsub__(self, o): return self._bin(o, "sub", True)
    def __mul__(self, o): return self._bin(o, "mul")
    def __rmul__(self, o): return self._bin(o, "mul", True)
    def __truediv__(self, o): return self._bin(o, "div")
    def __rtruediv__(self, o): return self._bin(o, "div", True)


class Lanes(_Arithmetic):
    """A float register of a kernel being recorded: one value per fragment. Arithmetic
    (+ - * / and unary -) with Lanes or Python numbers, comparisons giving a Mask, abs() and
    math.floor(); a Python `if` on it raises (use select)."""

    __slots__ = ("_r", "id")

    def __init__(self, recorder, node):
        self._r, self.id = recorder, node

    def _bin(self, other, op, swap=False):
        if isinstance(other, Vec4):
            return (Vec4.splat(self) if not swap else other)._bin(other if not swap else self, op)
        o = _lanes(self._r, other)
        a, b = (o, self) if swap else (self, o)
        return Lanes(self._r, self._r.push(op, a.id, b.id))

    def __neg__(self): return Lanes(self._r, self._r.push("neg", self.id))
    def __pos__(self): return self
    def __abs__(self): return Lanes(self._r, self._r.push("abs", self.id))
    def __floor__(self): return Lanes(self._r, self._r.push("floor", self.id))

    def _cmp(self, other, op):
        return Mask(self._r, self._r.push(op, self.id, _lanes(self._r, other).id))

    def __lt__(self, o): return self._cmp(o, "lt")
    def __le__(self, o): return self._cmp(o, "le")
    def __gt__(self, o): return self._cmp(o, "gt")
    def __ge__(self, o): return self._cmp(o, "ge")
    def __eq__(self, o): return self._cmp(o, "eq")
    def __ne__(self, o): return self._cmp(o, "ne")
    __hash__ = None

    def __bool__(self): _refuse_truth(self._r, "if/and/or/not")
    def __float__(self): _refuse_truth(self._r, "float()")
    def __index__(self): _refuse_truth(self._r, "int()")
    def __repr__(self): return f"<vgpu_rt.Lanes node {self.id}>"


class Mask:
    """A mask register of a kernel being recorded: one bool per fragment. & | ~ combine masks
    (a constant operand folds away, as in C++); a Python `if`, `and`, `or` or `not` raises."""

    __slots__ = ("_r", "id")

    def __init__(self, recorder, node):
        self._r, self.id = recorder, node

    def __and__(self, other):
        o = _mask(self._r, other)
        if self.id == self._r.mask_true:
            return o
        if o.id == self._r.mask_true:
            return self
        return Mask(self._r, self._r.push("mask_and", self.id, o.id))

    def __or__(self, other):
        o = _mask(self._r, other)
        if self.id == self._r.mask_false:
            return o
        if o.id == self._r.mask_false:
            return self
        return Mask(self._r, self._r.push("mask_or", self.id, o.id))

    __rand__ = __and__
    __ror__ = __or__

    def __invert__(self): return Mask(self._r, self._r.push("mask_not", self.id))
    def __bool__(self): _refuse_truth(self._r, "if/and/or/not")
    def __repr__(self): return f"<vgpu_rt.Mask node {self.id}>"


class Vec4(_Arithmetic):
    """Four Lanes (.x .y .z .w, or [0] to [3]): a texel, an output. Arithmetic is per component;
    a Lanes or a Python number on the other side is broadcast."""

    __slots__ = ("x", "y", "z", "w")

    def __init__(self, x, y, z, w):
        r = _recorder_of(x, y, z, w)  # numbers beside lane values become constants
        if r is not None:
            x, y, z, w = (_lanes(r, v) for v in (x, y, z, w))
        self.x, self.y, self.z, self.w = x, y, z, w

    @staticmethod
    def splat(v):
        return Vec4(v, v, v, v)

    def __getitem__(self, i):
        return (self.x, self.y, self.z, self.w)[i]

    def __iter__(self):
        return iter((self.x, self.y, self.z, self.w))

    def __len__(self):
        return 4

    def _bin(self, other, op, swap=False):
        if not isinstance(other, Vec4):
            r = self.x._r
            other = Vec4.splat(_lanes(r, other))
        return Vec4(*(a._bin(b, op, swap) for a, b in zip(self, other)))

    def __neg__(self): return Vec4(*(-a for a in self))
    def __abs__(self): return Vec4(*(abs(a) for a in self))
    def __bool__(self): _refuse_truth(self.x._r, "if/and/or/not")
    def __repr__(self): return f"<vgpu_rt.Vec4 nodes {[a.id for a in self]}>"


def _recorder_of(*values):
    for v in values:
        if isinstance(v, (Lanes, Mask)):
            return v._r
        if isinstance(v, Vec4):
            r = _recorder_of(*v)
            if r is not None:
                return r
    return None


def _lanes(r, v):
    if isinstance(v, Lanes):
        return v
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        r.fail(f"expected a lane value or a number, got {type(v).__name__}")
    return Lanes(r, r.push("constant", value=v))


def _mask(r, m):
    if isinstance(m, Mask):
        return m
    if isinstance(m, bool):
        return Mask(r, r.mask_true if m else r.mask_false)
    r.fail(f"expected a mask (a comparison of lane values) or a bool, got {type(m).__name__}")


def _unary(op, v):
    r = _recorder_of(v)
    if r is None:
        raise KernelError(f"{_user_line()}: vgpu_rt.{op} takes lane values (inside a kernel)")
    if isinstance(v, Vec4):
        return Vec4(*(_unary(op, a) for a in v))
    return Lanes(r, r.push(op, _lanes(r, v).id))


def select(m, a, b):
    """Per fragment, a where the mask m holds, else b (Lanes, Vec4 or numbers)."""
    r = _recorder_of(m, a, b)
    if r is None:
        raise KernelError(f"{_user_line()}: vgpu_rt.select takes lane values (inside a kernel)")
    m = _mask(r, m)
    if isinstance(a, Vec4) or isinstance(b, Vec4):
        a = a if isinstance(a, Vec4) else Vec4.splat(_lanes(r, a))
        b = b if isinstance(b, Vec4) else Vec4.splat(_lanes(r, b))
        return Vec4(*(select(m, p, q) for p, q in zip(a, b)))
    a, b = _lanes(r, a), _lanes(r, b)
    return Lanes(r, r.push("select", m.id, a.id, b.id))


def floor(v):
    """Per fragment, the largest whole number not above v."""
    return _unary("floor", v)


def sqrt(v):
    """Per fragment, the square root of v."""
    return _unary("sqrt", v)


def rsqrt(v):
    """Per fragment, 1 / sqrt(v) (the vgpu's two correctly rounded steps)."""
    return _unary("rsqrt", v)


def _minmax(op, a, b):
    r = _recorder_of(a, b)
    if r is None:
        raise KernelError(f"{_user_line()}: {op} takes lane values (inside a kernel)")
    if isinstance(a, Vec4) or isinstance(b, Vec4):
        a = a if isinstance(a, Vec4) else Vec4.splat(_lanes(r, a))
        b = b if isinstance(b, Vec4) else Vec4.splat(_lanes(r, b))
        return Vec4(*(_minmax(op, p, q) for p, q in zip(a, b)))
    a, b = _lanes(r, a), _lanes(r, b)
    return Lanes(r, r.push(op, a.id, b.id))


class _Outputs:
    def __init__(self, r):
        self._r = r

    def __setitem__(self, i, value):
        r = self._r
        if not isinstance(i, int) or not 0 <= i < len(r.outputs):
            r.fail(f"output {i!r}, but the kernel writes outputs 0 to {len(r.outputs) - 1} "
                   f"(outputs={len(r.outputs)})")
        if isinstance(value, (Lanes, int, float)) and not isinstance(value, bool):
            value = Vec4.splat(_lanes(r, value))
        if not isinstance(value, Vec4):
            if not isinstance(value, (tuple, list)) or len(value) != 4:
                r.fail(f"f.out[{i}] takes a Vec4 or four values, got {type(value).__name__}")
            value = Vec4(*(_lanes(r, v) for v in value))
        r.outputs[i] = [c.id for c in value]

    def __getitem__(self, i):
        r = self._r
        if not isinstance(i, int) or not 0 <= i < len(r.outputs):
            r.fail(f"output {i!r}, but the kernel writes outputs 0 to {len(r.outputs) - 1}")
        return Vec4(*(Lanes(r, n) for n in r.outputs[i]))


class _Branch:
    def __init__(self, r):
        self._r = r

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def __bool__(self):  # `if f.branch(m):`, as in C++
        return True


class Fragments:
    """What a kernel's function is given: the fragments of a pass, recorded (one call). Its
    operations are the vgpu's (vgpu/fragment.h): fetch, fetch_own, x, y, out[i], discard, branch,
    loop; select, min, max, abs, floor, sqrt, rsqrt; uniform(name), or f.NAME."""

    def __init__(self, r):
        self._r = r
        self.out = _Outputs(r)

    @property
    def x(self):
        """The fragment's window position: pixel centres, x + 0.5."""
        return Lanes(self._r, self._r.frag_x)

    @property
    def y(self):
        return Lanes(self._r, self._r.frag_y)

    def _unit(self, unit):
        n = len(self._r.kernel.units)
        if isinstance(unit, bool) or not isinstance(unit, int) or not 0 <= unit < n:
            self._r.fail(f"texture unit {unit!r}, but the kernel names {n} unit"
                         f"{'' if n == 1 else 's'} (units={list(self._r.kernel.units)!r})")
        return unit

    def _texel(self, node):
        r = self._r
        return Vec4(*(Lanes(r, r.push("channel", node, unit=c)) for c in range(4)))

    def fetch(self, unit, u, v):
        """texRECT: the texel of `unit` at texel coordinates (u, v), nearest, clamped."""
        r, unit = self._r, self._unit(unit)
        u, v = _lanes(r, u), _lanes(r, v)
        if u.id == r.frag_x and v.id == r.frag_y:
            return self._texel(r.push("fetch_own", unit=unit))
        return self._texel(r.push("fetch", u.id, v.id, unit=unit))

    def fetch_own(self, unit):
        """This fragment's own texel of `unit` (a texture the size of the target)."""
        return self._texel(self._r.push("fetch_own", unit=self._unit(unit)))

    def discard(self, mask):
        """Kills the fragments where mask holds: they write nothing, a query skips them."""
        r = self._r
        r.kill = (Mask(r, r.kill) | _mask(r, mask)).id

    def branch(self, mask):
        """A conditional block, `with f.branch(m):` (or `if f.branch(m):`). Recorded as the
        vgpu's recordings are today: straight-line, both sides run (write results through
        select). Not inside a loop body."""
        _mask(self._r, mask)
        if self._r.in_loop:
            self._r.fail("f.branch inside a loop body; write the body with selects")
        return _Branch(self._r)

    def loop(self, max_iterations, body, active=True, carry=None):
        """A data-dependent loop (the fp40 LOOP/BRK shape): while some lane is active and the
        budget lasts, active = active & body(active). body writes its results through
        select(active, new, old). With carry (a tuple of values), body(active, carry) returns
        (more, carry) and loop returns (lanes still looping, carry); without, body(active)
        returns more (carry values through nonlocal) and loop returns the lanes still looping.
        One loop per kernel, on profiles with loops (gf6600 and later)."""
        r = self._r
        if r.loop is not None or r.in_loop:
            r.fail("a second loop; the vgpu models one loop per program")
        if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) \
                or max_iterations < 0:
            r.fail(f"max_iterations must be a whole number >= 0, got {max_iterations!r}")
        entry = _mask(r, active)
        if carry is not None:  # numbers become registers before the loop (carried, not folded)
            carry = tuple(v if isinstance(v, (Lanes, Vec4)) else _lanes(r, v) for v in carry)

        def once(on, state):
            got = body(on) if carry is None else body(on, state)
            if carry is not None:
                if not isinstance(got, tuple) or len(got) != 2:
                    r.fail("a loop body with carry returns (more, carry)")
                more, state = got
            else:
                more = got
            return _mask(r, more), state

        begin = len(r.nodes)
        r.in_loop = True
        try:
            more, state = once(entry, carry)
            nxt = r.push("mask_and", entry.id, more.id)
            mid = len(r.nodes)
            more, state = once(Mask(r, nxt), state)
            after = r.push("mask_and", nxt, more.id)
        finally:
            r.in_loop = False
        r.loop = (begin, mid, len(r.nodes), max_iterations, entry.id)
        return Mask(r, after) if carry is None else (Mask(r, after), state)

    def select(self, m, a, b):
        return select(m, a, b)

    def min(self, a, b):
        """Per fragment, a < b ? a : b (ARB_fragment_program MIN)."""
        return _minmax("min", a, b)

    def max(self, a, b):
        return _minmax("max", a, b)

    def abs(self, v):
        return _unary("abs", v)

    def floor(self, v):
        return _unary("floor", v)

    def sqrt(self, v):
        return _unary("sqrt", v)

    def rsqrt(self, v):
        return _unary("rsqrt", v)

    def uniform(self, name):
        """The uniform's value as bound for this run (a constant of the recording)."""
        r = self._r
        if name not in r.uniforms:
            r.fail(f"no uniform {name!r} (its uniforms: {', '.join(r.uniforms) or 'none'})")
        node = r.push("constant", value=r.uniforms[name])
        r.uniform_nodes.setdefault(name, []).append(node)
        return Lanes(r, node)

    def __getattr__(self, name):
        if name.startswith("_") or name not in self._r.uniforms:
            raise AttributeError(f"kernel '{self._r.kernel.name}' has no uniform or fragment "
                                 f"operation {name!r}")
        return self.uniform(name)


class UserKernel:
    """A kernel written in Python (made by @vgpu_rt.kernel): run it with Device.run as the
    project's kernels. name, units, outputs, uniforms (the defaults); analyze(), instructions,
    glsl() and check(profile) record it with the defaults or the uniforms given."""

    def __init__(self, fn, units, outputs, uniforms, name, stage=None):
        self.name, self.stage = name, stage
        if stage is not None:
            known = stages()
            if stage not in known:
                raise KernelError(f"kernel '{name}': no stage {stage!r} (the frame's stages: "
                                  f"{', '.join(known)})")
            if units is None:
                units = known[stage].default_units
            uniforms = {**known[stage].uniforms, **(uniforms or {})}
        elif units is None:
            units = ()
        if not callable(fn):
            raise KernelError(f"kernel '{name}': expected a function, got {type(fn).__name__}")
        try:
            params = list(_inspect.signature(fn).parameters.values())
        except (TypeError, ValueError):
            params = None
        if params is not None:
            positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
                          and p.default is p.empty]
            varargs = any(p.kind == p.VAR_POSITIONAL for p in params)
            if len(positional) > 1 or (not positional and not varargs):
                raise KernelError(
                    f"kernel '{name}': its function takes {len(positional)} arguments; a kernel "
                    "takes one, the fragments (def k(f): ...)")
        if isinstance(units, str) or not all(isinstance(u, str) for u in units):
            raise KernelError(f"kernel '{name}': units must be a list of names, got {units!r}")
        if isinstance(outputs, bool) or not isinstance(outputs, int) or outputs < 1:
            raise KernelError(f"kernel '{name}': outputs must be a whole number >= 1, "
                              f"got {outputs!r}")
        self.fn, self.units, self.outputs = fn, list(units), outputs
        self.uniforms = self._bind(dict(uniforms or {}), {})
        self._programs = {}

    def _bind(self, defaults, given):
        values = dict(defaults)
        for key, value in (given or {}).items():
            if key not in values:
                known = ", ".join(values) or "none"
                raise KernelError(f"kernel '{self.name}' has no uniform {key!r} "
                                  f"(its uniforms: {known})")
            values[key] = value
        for key, value in values.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise KernelError(f"kernel '{self.name}': uniform {key!r} is "
                                  f"{type(value).__name__} {value!r}; a uniform is a number")
            if value != value:
                raise KernelError(f"kernel '{self.name}': uniform {key!r} is NaN; a uniform "
                                  "must be a number (NaN would reach every fragment)")
        return values

    def _record(self, uniforms):
        r = _Recorder(self, uniforms)
        try:
            self.fn(Fragments(r))
        except KernelError:
            raise
        except Exception as e:  # the user's own code failed: its line, one line
            where = "?"
            for entry in reversed(_traceback.extract_tb(e.__traceback__)):
                if not _is_ours(entry.filename):
                    where = f"{entry.filename}, line {entry.lineno}"
                    break
            raise KernelError(f"kernel '{self.name}', {where}: {type(e).__name__}: "
                              f"{_one_line(e)}") from None
        kill = -1 if r.kill == r.mask_false else r.kill
        return _ext.record_kernel(self.name, self.outputs, self.units, r.nodes, r.outputs, kill,
                                  r.loop, list(r.uniform_nodes.items()))

    def recorded(self, uniforms=None):
        """The recording (vgpu::RecordedProgram) with these uniforms over the defaults."""
        values = self._bind(self.uniforms, uniforms)
        key = tuple(sorted(values.items()))
        if key not in self._programs:
            if len(self._programs) >= 16:  # a sweep over uniforms keeps the last few
                self._programs.clear()
            try:
                self._programs[key] = self._record(values)
            except KernelError:
                raise
            except ValueError as e:  # the extension refused the recording
                raise KernelError(_one_line(e)) from None
        return self._programs[key]

    def check(self, profile, uniforms=None):
        """Raises KernelError with the card's rule this kernel breaks on `profile` (a profile's
        name), naming the rule, the card, both numbers and the built-in profiles it fits."""
        try:
            _ext.check_units(self.name, len(self.units), profile)
            _ext.check_kernel(self.recorded(uniforms), profile)
        except KernelError:
            raise
        except ValueError as e:
            raise KernelError(_one_line(e)) from None

    def analyze(self, uniforms=None):
        """The counting run: instructions, fetches per unit, the loop's figures."""
        return self.recorded(uniforms).analyze()

    @property
    def instructions(self):
        """Static instructions per fragment with the default uniforms."""
        return self.analyze()["instructions"]

    def glsl(self, uniforms=None):
        """The GLSL fragment shader the GL device compiles from this kernel's recording."""
        return self.recorded(uniforms).glsl()

    def __repr__(self):
        return f"<vgpu_rt.UserKernel {self.name} units={self.units} outputs={self.outputs}>"


class Stage:
    """A stage of the frame a kernel can replace (vgpu_rt.stages()[name]): the textures it binds
    (`units`: every name a kernel may give its units; `default_units`: those a scene without
    base-colour textures has) and the uniforms the frame sets before each of its passes, with
    their defaults (`uniforms`)."""

    def __init__(self, name, units, uniforms):
        self.name, self.units, self.uniforms = name, list(units), dict(uniforms)
        self.default_units = [u for u in self.units
                              if u not in ("uvs01", "uvs2", "texture_table", "texture_atlas")]

    def __repr__(self):
        return f"<vgpu_rt.Stage {self.name} units={self.units} uniforms={list(self.uniforms)}>"


_STAGES = None


def stages():
    """The frame's stages a kernel of your own can replace, by name: "shader" (one pass per
    light, output 0 the result texel: rgb so far plus this light's share, w the reflected ray's
    weight) and "camera" (the primary rays: output 0 the direction in xyz, tmax in w)."""
    global _STAGES
    if _STAGES is None:
        _STAGES = {name: Stage(name, units, uniforms)
                   for name, (units, uniforms) in _ext.stages().items()}
    return _STAGES


def kernel(fn=None, *, units=None, outputs=1, uniforms=None, name=None, stage=None):
    """Makes a Python function a kernel (a fragment program), recorded when it is run:

        @vgpu_rt.kernel(units=["values"], outputs=1, uniforms={"gain": 2.0})
        def scale(f):
            f.out[0] = f.fetch_own(0) * f.gain
        vgpu_rt.Device("gf5700").run(scale, [a], [o], uniforms={"gain": 3.0})

    units names the texture units (unit i is units[i]); outputs the render targets it writes;
    uniforms the uniforms and their defaults, bound again by Device.run(..., uniforms=...).

    stage="shader" or "camera" makes it a stage of the frame of your own, for
    vgpu_rt.render(scene, shader=..., camera=...): its units are named from the stage's textures
    (default: all of them but the base-colour textures'), and it has the stage's uniforms
    (vgpu_rt.stages()[stage].uniforms: f.light_x, f.first_light, f.width, ...), which the frame
    sets before each of its passes, besides its own:

        @vgpu_rt.kernel(stage="shader", units=["surface", "result", "colors"])
        def flat(f): ..."""
    def wrap(f):
        return UserKernel(f, units, outputs, uniforms, name or getattr(f, "__name__", "kernel"),
                          stage)
    return wrap(fn) if fn is not None else wrap


