"""Kernels written in Python (issue 48): recorded once, run by the vgpu as the project's kernels,
checked against the card's rules with one line each, and refused with the user's line where the
function does what a fragment program cannot."""

import inspect
import math
import unittest

import numpy as np

import vgpu_rt

F32 = np.float32


def texture(dev, name, texels):
    """A texture holding `texels`, an (height, width, 4) array."""
    texels = np.asarray(texels, dtype=F32)
    t = dev.texture(name, texels.shape[1], texels.shape[0], 4)
    t.write(texels)
    return t


def line_of(fn, text):
    """The file line of fn's source line containing `text`."""
    lines, first = inspect.getsourcelines(fn)
    return first + next(i for i, line in enumerate(lines) if text in line)


@vgpu_rt.kernel(units=["a", "b"], outputs=1, uniforms={"gain": 2.0})
def every_operation(f):
    a = f.fetch_own(0)
    b = f.fetch(1, f.x + 1.0, f.y)  # the texel to the right (clamped at the edge)
    s = a * f.gain - b / 4.0
    m = (a.x > b.x) | ~(a.y <= 0.5)
    with f.branch(m):
        pick = vgpu_rt.select(m, a.z, -b.z)
    f.out[0] = (f.min(s.x, s.y) + f.max(a.w, b.w), abs(s.z) + math.floor(a.w * 2.5),
                vgpu_rt.sqrt(abs(a.x)) * vgpu_rt.rsqrt(abs(b.y) + 2.0), pick + f.x - f.y)
    f.discard((a.x == 7.0) & (b.x != 0.0))


def every_operation_in_numpy(a, b, gain):
    """every_operation in float32, operation by operation (np.float32 rounds each)."""
    h, w = a.shape[:2]
    right = np.concatenate([b[:, 1:], b[:, -1:]], axis=1)
    s = a * F32(gain) - right / F32(4)
    m = (a[..., 0] > right[..., 0]) | ~(a[..., 1] <= F32(0.5))
    pick = np.where(m, a[..., 2], -right[..., 2])
    ys, xs = np.mgrid[0:h, 0:w].astype(F32) + F32(0.5)
    out = np.stack([np.minimum(s[..., 0], s[..., 1]) + np.maximum(a[..., 3], right[..., 3]),
                    np.abs(s[..., 2]) + np.floor(a[..., 3] * F32(2.5)),
                    np.sqrt(np.abs(a[..., 0])) * (F32(1) / np.sqrt(np.abs(right[..., 1]) + F32(2))),
                    pick + xs - ys], axis=-1).astype(F32)
    kill = (a[..., 0] == F32(7)) & (right[..., 0] != F32(0))
    return out, kill


@vgpu_rt.kernel(units=["intersection", "triangle_materials"], outputs=1, uniforms={"width": 1.0})
def keep_hits(f):
    """kernels/keep_hits.h, written again in Python."""
    hit = f.fetch_own(0)
    hits = hit.w >= 0.0
    tri = f.max(hit.w, 0.0)
    row = f.floor((tri + 0.5) / f.width)  # kernels/common.h's id_to_texel
    material = f.fetch(1, tri - row * f.width + 0.5, row + 0.5).x
    f.out[0] = (1.0, vgpu_rt.select(hits, material, -1.0), 0.0, 0.0)


@vgpu_rt.kernel(units=["stream"], outputs=1, uniforms={"rows": 0.0})
def copy_rows(f):
    """kernels/copy_rows.h, written again in Python."""
    f.out[0] = f.fetch(0, f.x, f.y + f.rows)


@vgpu_rt.kernel(units=["values"], outputs=1)
def halvings(f):
    v = f.fetch_own(0).x

    def body(active, state):
        x, n = state
        x = vgpu_rt.select(active, x * 0.5, x)
        n = vgpu_rt.select(active, n + 1.0, n)
        return x > 1.0, (x, n)

    left, (x, n) = f.loop(16, body, active=v > 1.0, carry=(v, 0.0))
    f.out[0] = (x, n, vgpu_rt.select(left, 1.0, 0.0), 0.0)


@vgpu_rt.kernel(units=["values"], outputs=1)
def double(f):
    v = f.fetch_own(0)
    f.out[0] = v * 2.0


class KernelsFromPythonTest(unittest.TestCase):
    def test_a_python_kernel_over_hand_made_texels_writes_every_channel_as_numpy_computes_it(self):
        dev = vgpu_rt.Device("gf5700")
        rng = np.random.default_rng(48)
        a = rng.uniform(-4, 4, (3, 5, 4)).astype(F32)
        b = rng.uniform(-4, 4, (3, 5, 4)).astype(F32)
        a[1, 2, 0], b[1, 3, 0] = 7.0, 1.0  # one fragment discarded
        a[0, 0, 0], b[0, 1, 0] = 7.0, 0.0  # and one not (b.x == 0)
        want, kill = every_operation_in_numpy(a, b, 2.0)
        self.assertEqual(int(kill.sum()), 1)
        out = texture(dev, "out", np.full((3, 5, 4), -99.0))
        r = dev.run(every_operation, [texture(dev, "a", a), texture(dev, "b", b)], [out],
                    query=True)
        got = out.array
        want[kill] = -99.0  # a discarded fragment writes nothing
        for c in range(4):
            self.assertTrue(np.array_equal(got[..., c], want[..., c]), (c, got[..., c], want[..., c]))
        self.assertEqual(r["query"], 14)
        self.assertEqual(r["kernel"], "every_operation")
        self.assertEqual(r["counters"]["texture_fetches"], 15 * 2)

    def test_the_issue_s_double_runs_as_the_project_s_kernels_do(self):
        dev = vgpu_rt.Device("gf5700")
        texels = np.arange(2 * 3 * 4, dtype=F32).reshape(2, 3, 4) - 5
        o = dev.texture("o", 3, 2)
        r = dev.run(double, [texture(dev, "a", texels)], [o])
        self.assertTrue(np.array_equal(o.array, texels * 2))
        self.assertEqual(double.instructions, 5)  # a fetch and four multiplications
        self.assertEqual(r["counters"]["instructions"], 6 * 5)

    def test_keep_hits_in_python_is_the_project_s_bit_for_bit_with_the_same_counters(self):
        for profile in ("gf5700", "gf6600"):
            dev = vgpu_rt.Device(profile)
            hits = np.zeros((2, 3, 4), dtype=F32)
            hits[..., 3] = [[-1, 0, 1], [2.5, 3, -0.0]]
            hits[..., 0] = 9
            mats = np.zeros((4, 1, 4), dtype=F32)
            mats[:, 0, 0] = [10.5, 11.25, 12.125, 13.0625]
            units = [texture(dev, "intersection", hits), texture(dev, "materials", mats)]
            outs = []
            for k in (vgpu_rt.kernels["keep hits"], keep_hits):
                o = dev.texture("marks", 3, 2)
                r = dev.run(k, units, [o], query=True)
                outs.append((o.array.copy(), r))
            (want, rc), (got, rp) = outs
            self.assertEqual(got.tobytes(), want.tobytes(), (profile, got, want))
            self.assertEqual(want[1, 0, 1], 13.0625)  # 2.5 -> row 3
            self.assertEqual(rp["counters"], rc["counters"], profile)
            self.assertEqual(rp["query"], rc["query"])
        self.assertEqual(keep_hits.instructions, vgpu_rt.kernels["keep hits"].instructions)
        self.assertEqual(keep_hits.analyze()["fetches"][:2], [1, 1])

    def test_copy_rows_in_python_is_the_project_s_and_its_uniform_moves_the_rows(self):
        dev = vgpu_rt.Device("gf6600")
        texels = np.arange(4 * 2 * 4, dtype=F32).reshape(4, 2, 4)
        stream = texture(dev, "stream", texels)
        o1, o2 = dev.texture("o1", 2, 4), dev.texture("o2", 2, 4)
        r1 = dev.run(vgpu_rt.kernels["row copy"], [stream], [o1])
        r2 = dev.run(copy_rows, [stream], [o2])
        self.assertEqual(o2.array.tobytes(), o1.array.tobytes())
        self.assertEqual(r2["counters"], r1["counters"])
        dev.run(copy_rows, [stream], [o2], uniforms={"rows": 1.0})
        self.assertTrue(np.array_equal(o2.array, np.concatenate([texels[1:], texels[3:]])))

    def test_uniforms_are_bound_when_the_kernel_runs_and_the_defaults_stay(self):
        dev = vgpu_rt.Device("gf5700")

        @vgpu_rt.kernel(units=["values"], uniforms={"gain": 2.0, "bias": 0.0})
        def scale(f):
            f.out[0] = f.fetch_own(0) * f.uniform("gain") + f.bias

        a = texture(dev, "a", np.full((1, 2, 4), 1.5))
        o = dev.texture("o", 2, 1)
        for given, want in (({}, 3.0), ({"gain": 3.0}, 4.5), ({"gain": 0.5, "bias": 1.0}, 1.75),
                            (None, 3.0)):
            dev.run(scale, [a], [o], uniforms=given)
            self.assertTrue(np.all(o.array == want), (given, o.array))
        self.assertEqual(scale.uniforms, {"gain": 2.0, "bias": 0.0})
        self.assertEqual(scale.analyze({"gain": 9.0}), scale.analyze())

    def test_a_loop_runs_on_gf6600_and_counts_each_fragment_s_iterations(self):
        dev = vgpu_rt.Device("gf6600")
        v = np.zeros((1, 4, 4), dtype=F32)
        v[0, :, 0] = [5, 0.5, 1000, 1e9]
        o = dev.texture("o", 4, 1)
        r = dev.run(halvings, [texture(dev, "v", v)], [o])
        got = o.array[0]
        self.assertEqual(got[:, 0].tolist(), [0.625, 0.5, 1000 / 1024, 1e9 / 2 ** 16])
        self.assertEqual(got[:, 1].tolist(), [3, 0, 10, 16])
        self.assertEqual(got[:, 2].tolist(), [0, 0, 0, 1])  # the last ran out of budget
        self.assertEqual(r["counters"]["loop_iterations"], 29)
        self.assertEqual(halvings.analyze()["loops"], 1)

    def test_each_card_rule_is_one_line_naming_the_rule_the_card_both_numbers_and_where_it_fits(self):
        dev = vgpu_rt.Device("gf5700")
        a = texture(dev, "a", np.zeros((1, 1, 4)))
        o, o2 = dev.texture("o", 1, 1), dev.texture("o2", 1, 1)

        @vgpu_rt.kernel(units=["values"])
        def long(f):
            v = f.fetch_own(0).x
            for _ in range(1099):  # and the fetch: 1100 instructions
                v = v + 1.0
            f.out[0] = (v, v, v, v)

        @vgpu_rt.kernel(units=["values"], outputs=2)
        def two(f):
            f.out[0] = f.fetch_own(0)
            f.out[1] = f.fetch_own(0) * 2.0

        @vgpu_rt.kernel(units=["u%d" % i for i in range(17)])
        def many(f):
            f.out[0] = f.fetch_own(16)

        cases = [
            (long, [a], [o], "program 'long' has 1100 instructions; profile gf5700 allows 1024; "
                             "it fits gf6600, rtx4090, h200 and h100"),
            (two, [a], [o, o2], "program 'two' writes 2 outputs; profile gf5700 allows 1 (no "
                                "multiple render targets); it fits r300, gf6600, rtx4090, "
                                "h200 and h100"),
            (halvings, [a], [o], "program 'halvings' has a data-dependent loop of up to 16 "
                                 "iterations; profile gf5700 (fp30) has no dynamic branching or "
                                 "loops (0 iterations); it fits gf6600, rtx4090, h200 and h100"),
            (many, [a], [o], "program 'many' reads texture unit 16 (17 units); profile gf5700 has "
                             "16 texture units (GL_MAX_TEXTURE_IMAGE_UNITS)"),
            (double, [o], [o], "program 'double' reads texture 'o' (unit 0) while rendering to it: "
                               "read/write hazard, use ping-pong"),
        ]
        for k, units, targets, line in cases:
            with self.assertRaises(ValueError) as e:
                dev.run(k, units, targets)
            self.assertEqual(str(e.exception), line)
        with self.assertRaises(vgpu_rt.KernelError) as e:
            many.check("rtx4090")  # the card has 32; the emulator binds 16
        self.assertEqual(str(e.exception), "program 'many' reads texture unit 16 (17 units); the "
                                           "vgpu binds 16 texture units")
        dev6 = vgpu_rt.Device("gf6600")
        dev6.run(long, [a], [o])  # what gf5700 refused, gf6600 runs
        self.assertEqual(float(o.array[0, 0, 0]), 1099.0)
        dev6.run(two, [a], [o, o2])
        with self.assertRaises(ValueError) as e:
            vgpu_rt.Device("r300").run(long, [a], [o])
        self.assertEqual(str(e.exception), "program 'long' has 1100 instructions; profile r300 "
                                           "allows 288; it fits gf6600, rtx4090, h200 and h100")

    def test_a_python_if_on_a_lane_value_raises_naming_the_user_s_line(self):
        @vgpu_rt.kernel(units=["values"])
        def branchy(f):
            v = f.fetch_own(0)
            if v.x > 0.0:  # the line
                v = v * 2.0
            f.out[0] = v

        with self.assertRaises(vgpu_rt.KernelError) as e:
            branchy.check("gf5700")
        self.assertEqual(str(e.exception),
                         f"kernel 'branchy', {__file__}, line {line_of(branchy.fn, '# the line')}: "
                         "a Python if/and/or/not on a lane value cannot be recorded (each fragment "
                         "has its own value); choose per fragment with vgpu_rt.select(mask, a, b), "
                         "f.min/f.max, or `with f.branch(mask):`")
        self.assertIsInstance(e.exception, ValueError)

        @vgpu_rt.kernel(units=["values"])
        def builtin_max(f):
            f.out[0] = (max(f.x, f.y), 0.0, 0.0, 0.0)  # max() asks `if`

        with self.assertRaisesRegex(vgpu_rt.KernelError, "line %d: a Python if"
                                    % line_of(builtin_max.fn, "max(f.x")):
            builtin_max.instructions

    def test_bad_kernels_raise_one_line_and_never_crash(self):
        dev = vgpu_rt.Device("gf5700")
        a = texture(dev, "a", np.zeros((1, 1, 4)))
        o = dev.texture("o", 1, 1)
        with self.assertRaises(vgpu_rt.KernelError) as e:
            vgpu_rt.kernel(units=["values"])(lambda f, g: None)
        self.assertEqual(str(e.exception), "kernel '<lambda>': its function takes 2 arguments; a "
                         "kernel takes one, the fragments (def k(f): ...)")

        @vgpu_rt.kernel(units=["values"])
        def unknown_unit(f):
            f.out[0] = f.fetch_own(1)

        @vgpu_rt.kernel(units=["values"])
        def oops(f):
            f.out[0] = f.fetch_own(0) * (1 / 0)

        @vgpu_rt.kernel(units=["values"], uniforms={"gain": 1.0})
        def scale(f):
            f.out[0] = f.fetch_own(0) * f.gain

        where = f"{__file__}, line"
        cases = [
            (unknown_unit, None, f"kernel 'unknown_unit', {where} "
             f"{line_of(unknown_unit.fn, 'fetch_own(1)')}: texture unit 1, but the kernel names 1 "
             "unit (units=['values'])"),
            (oops, None, f"kernel 'oops', {where} {line_of(oops.fn, '1 / 0')}: ZeroDivisionError: "
             "division by zero"),
            (scale, {"gain": float("nan")}, "kernel 'scale': uniform 'gain' is NaN; a uniform must "
             "be a number (NaN would reach every fragment)"),
            (scale, {"gian": 2.0}, "kernel 'scale' has no uniform 'gian' (its uniforms: gain)"),
        ]
        for k, uniforms, line in cases:
            with self.assertRaises(vgpu_rt.KernelError) as e:
                dev.run(k, [a], [o], uniforms=uniforms)
            self.assertEqual(str(e.exception), line)
            self.assertNotIn("\n", str(e.exception))
        with self.assertRaisesRegex(vgpu_rt.KernelError, "uniform 'gain' is NaN"):
            vgpu_rt.kernel(uniforms={"gain": math.nan})(lambda f: None)
        dev.run(scale, [a], [o], uniforms={"gain": 2.0})  # the device still works

    def test_the_recording_prints_as_the_gl_device_s_shader(self):
        text = keep_hits.glsl()
        self.assertIn("#version 330", text)
        self.assertIn("texelFetch", text)


if __name__ == "__main__":
    unittest.main()
