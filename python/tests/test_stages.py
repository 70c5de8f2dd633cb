"""Kernels written in Python in the frame (issue 48): a shader and a camera of one's own replace
the project's stages, on the emulator and the GL device, counted under their own names; a camera
that computes the project's rays gives its frame bit for bit; what cannot run is refused in one
line."""

import unittest

import numpy as np

import vgpu_rt
from vgpu_rt import Vec4, floor, rsqrt, select


@vgpu_rt.kernel(stage="camera")
def pinhole(f):
    """kernels::GenerateRays, operation for operation: the project's primary rays."""
    px = f.x + (f.jitter_x - 0.5)
    py = f.y + (f.jitter_y - 0.5)
    sx = (2.0 * px / f.width - 1.0) * (f.tan_half_fov * f.aspect)
    sy = (1.0 - 2.0 * py / f.height) * f.tan_half_fov
    d = [f.forward_x + f.right_x * sx + f.up_x * sy,
         f.forward_y + f.right_y * sx + f.up_y * sy,
         f.forward_z + f.right_z * sx + f.up_z * sy]
    s = rsqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    f.out[0] = Vec4(d[0] * s, d[1] * s, d[2] * s, f.far)


@vgpu_rt.kernel(stage="camera")
def fisheye(f):
    """A stereographic fisheye: (2 sx, 2 sy, 1 - r^2) / (1 + r^2) in the camera's basis."""
    k = 0.5 * f.tan_half_fov
    sx = (2.0 * (f.x + f.jitter_x - 0.5) / f.width - 1.0) * f.aspect * k
    sy = (1.0 - 2.0 * (f.y + f.jitter_y - 0.5) / f.height) * k
    r2 = sx * sx + sy * sy
    inv = 1.0 / (1.0 + r2)
    a, b, c = 2.0 * sx * inv, 2.0 * sy * inv, (1.0 - r2) * inv
    f.out[0] = Vec4(f.forward_x * c + f.right_x * a + f.up_x * b,
                    f.forward_y * c + f.right_y * a + f.up_y * b,
                    f.forward_z * c + f.right_z * a + f.up_z * b, f.far)


@vgpu_rt.kernel(stage="shader", units=["surface", "rays", "result", "colors", "normals0",
                                       "normals1", "normals2"], uniforms={"bands": 3.0})
def toon(f):
    """Diffuse light in bands, with the project's blend (the result so far plus w (1 - a) times
    this light's colour; the last light's pass sets the reflected ray's weight w a)."""
    surf, res = f.fetch_own(0), f.fetch_own(2)
    hit = surf.w >= 0.0
    row = floor((surf.w + 0.5) / f.scene_width)  # triangle id -> its texel
    u, v = surf.w - row * f.scene_width + 0.5, row + 0.5
    mat = f.fetch(3, u, v)
    n = f.fetch(4, u, v) + f.fetch(5, u, v) + f.fetch(6, u, v)
    n = n * rsqrt(n.x * n.x + n.y * n.y + n.z * n.z)
    d = f.fetch_own(1)
    to = [f.light_x - surf.x, f.light_y - surf.y, f.light_z - surf.z]
    facing = select(n.x * d.x + n.y * d.y + n.z * d.z > 0.0, -1.0, 1.0)
    lam = f.max((n.x * to[0] + n.y * to[1] + n.z * to[2]) * facing *
                rsqrt(to[0] * to[0] + to[1] * to[1] + to[2] * to[2]), 0.0)
    k = (floor(lam * f.bands + 0.5) / f.bands + f.first_light * f.ambient_r) * res.w * (1.0 - mat.w)
    weight = select(hit, res.w * mat.w, 0.0) * f.last_light + res.w * (1.0 - f.last_light)
    f.out[0] = Vec4(res.x + select(hit, mat.x * k * f.light_r, 0.0),
                    res.y + select(hit, mat.y * k * f.light_g, 0.0),
                    res.z + select(hit, mat.z * k * f.light_b, 0.0), weight)


def bits(a):
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


def passes_of(frame, name):
    return sum(k["passes"] for k in frame.stats["kernels"] if k["name"] == name)


def has_gl():
    try:
        vgpu_rt.render("sphere-alone", size="4x4", engine="gl")
        return True
    except ValueError:
        return False


class Stages(unittest.TestCase):
    def test_the_stages_list_their_units_and_uniforms(self):
        s = vgpu_rt.stages()
        self.assertEqual(sorted(s), ["camera", "shader"])
        self.assertEqual(s["shader"].units, vgpu_rt.kernels["shader"].units)
        self.assertEqual(s["shader"].uniforms["ambient_r"], np.float32(0.1))
        self.assertEqual(s["camera"].units, [])
        self.assertIn("jitter_x", s["camera"].uniforms)
        # A stage kernel has the stage's uniforms beside its own.
        self.assertIn("light_x", toon.uniforms)
        self.assertEqual(toon.uniforms["bands"], 3.0)

    def test_a_camera_that_computes_the_project_rays_gives_its_frame_bit_for_bit(self):
        for spp in (1, 4):
            with self.subTest(spp=spp):
                ours = vgpu_rt.render("classic", size="40x24", spp=spp)
                theirs = vgpu_rt.render("classic", size="40x24", spp=spp, camera=pinhole)
                self.assertTrue(np.array_equal(bits(ours.image), bits(theirs.image)))
                self.assertTrue(np.array_equal(ours.hit, theirs.hit))
                self.assertEqual(ours.stats["totals"]["passes"], theirs.stats["totals"]["passes"])
                self.assertEqual(passes_of(theirs, "pinhole"), spp)

    def test_a_toon_shader_and_a_fisheye_render_counted_under_their_names(self):
        ours = vgpu_rt.render("bunny", size="32x32")
        theirs = vgpu_rt.render("bunny", size="32x32", shader=toon, camera=fisheye)
        self.assertEqual(passes_of(theirs, "toon"), passes_of(ours, "shader"))
        self.assertEqual(passes_of(theirs, "shader"), 0)
        self.assertEqual(passes_of(theirs, "fisheye"), 1)
        self.assertFalse(np.array_equal(ours.image, theirs.image))
        self.assertGreater(float(theirs.image.sum()), 0.0)
        u = theirs.stats["user_kernels"]
        self.assertEqual(u["shader"]["program"], "toon")
        self.assertEqual(u["shader"]["instructions"], toon.instructions)
        self.assertEqual(u["camera"]["units"], [])
        self.assertNotIn("user_kernels", ours.stats)
        # Priced with the frame: the cost model reads its passes as any other.
        self.assertGreater(vgpu_rt.predict(theirs.stats, "gf6600")["total_ms"], 0.0)
        # A uniform of its own, bound before the frame.
        @vgpu_rt.kernel(stage="shader", units=toon.units, uniforms={"bands": 1.0}, name="toon")
        def one_band(f):
            toon.fn(f)
        other = vgpu_rt.render("bunny", size="32x32", shader=one_band, camera=fisheye)
        self.assertFalse(np.array_equal(other.image, theirs.image))

    def test_the_gl_device_runs_them_bit_for_bit_with_the_emulator(self):
        if not has_gl():
            self.skipTest("this build has no GL device")
        for scene, spp in (("bunny", 1), ("classic", 4)):
            with self.subTest(scene=scene):
                emu = vgpu_rt.render(scene, size="32x24", spp=spp, shader=toon, camera=fisheye)
                gl = vgpu_rt.render(scene, size="32x24", spp=spp, shader=toon, camera=fisheye,
                                    engine="gl")
                self.assertTrue(np.array_equal(bits(emu.image), bits(gl.image)))
                self.assertTrue(np.array_equal(emu.hit, gl.hit))
                self.assertEqual(passes_of(gl, "toon"), passes_of(emu, "toon"))

    def test_passes_show_a_kernel_of_ones_own_under_its_name(self):
        steps = vgpu_rt.passes("bunny", size="16x16", shader=toon)
        names = {p.kernel for p in steps}
        self.assertIn("toon", names)
        self.assertNotIn("shader", names)
        self.assertIsNotNone(steps.frame)

    def test_what_cannot_run_is_refused_in_one_line(self):
        cases = [
            (dict(camera=fisheye, engine="cpu"),
             "camera 'fisheye': the cpu engine runs no kernels (a double-precision reference); "
             "a kernel of your own needs --engine stream or gl"),
            (dict(camera=fisheye, beams="on"),
             "camera 'fisheye': --beams march the project's camera (generadorRayos) over tiles; "
             "a camera of your own needs --beams off"),
            (dict(camera=fisheye, aa="undersample:2"),
             "camera 'fisheye': --aa undersample:2 builds on the project's camera (gated sample "
             "rays, dense streams); a camera of your own takes --spp N (its jitter as uniforms) "
             "or no --aa"),
            (dict(shader=fisheye),
             "kernel 'fisheye' was written for the camera stage, not the shader stage"),
        ]
        for options, line in cases:
            with self.subTest(options=options):
                with self.assertRaises(ValueError) as e:
                    vgpu_rt.render("bunny", size="8x8", **options)
                self.assertEqual(str(e.exception), line)
        with self.assertRaises(TypeError):
            vgpu_rt.render("bunny", shader=vgpu_rt.kernels["shader"])

        @vgpu_rt.kernel(stage="shader", units=["surface", "normal"])
        def misnamed(f):
            f.out[0] = f.fetch_own(0)
        with self.assertRaises(ValueError) as e:
            vgpu_rt.render("bunny", size="8x8", shader=misnamed)
        self.assertEqual(str(e.exception).split(" (it binds")[0],
                         "shader 'misnamed': unit 1 'normal' is not a texture of the shading "
                         "stage (one pass per light)")

        # A rule of the card: a loop on gf5700 (fp30 has none); it fits gf6600.
        @vgpu_rt.kernel(stage="shader", units=["surface", "result"])
        def looping(f):
            res = f.fetch_own(1)
            _, (t,) = f.loop(4, lambda on, s: (s[0] < 3.0, (select(on, s[0] + 1.0, s[0]),)),
                             carry=(0.0,))
            f.out[0] = Vec4(res.x + t * 0.0, res.y, res.z, res.w)
        with self.assertRaises(vgpu_rt.KernelError) as e:
            vgpu_rt.render("bunny", size="8x8", shader=looping)
        self.assertIn("gf5700", str(e.exception))
        self.assertIn("it fits gf6600", str(e.exception))
        frame = vgpu_rt.render("bunny", size="8x8", shader=looping, profile="gf6600")
        self.assertGreater(passes_of(frame, "looping"), 0)


if __name__ == "__main__":
    unittest.main()
