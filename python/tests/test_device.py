"""vgpu_rt.Device, Texture and kernels: hand-made texels through one kernel, every channel read."""

import gc
import unittest

import numpy as np

import vgpu_rt


class DeviceTest(unittest.TestCase):
    def test_kernels_are_the_registry_s_list_by_name(self):
        k = vgpu_rt.kernels
        for name in ("generate rays", "traversal", "intersections", "shader", "accumulate samples"):
            self.assertIn(name, k)
        self.assertEqual(k["traversal"].paper_name, "traversal")
        self.assertEqual(k["traversal"].units, ["origins", "rays", "traversal", "intersection"])
        self.assertEqual(k["accumulate samples"].outputs, 1)
        self.assertGreater(k["intersections"].instructions, k["accumulate samples"].instructions)

    def test_a_texture_is_an_array_over_its_own_storage(self):
        dev = vgpu_rt.Device("gf5700")
        t = dev.texture("t", 256, 256, 4)
        a = t.array
        self.assertEqual(a.shape, (256, 256, 4))
        self.assertEqual(a.dtype, np.float32)
        self.assertFalse(a.flags["OWNDATA"])
        self.assertFalse(a.flags["WRITEABLE"])
        b = np.asarray(t)  # the buffer protocol: the same memory
        self.assertEqual(a.__array_interface__["data"][0], b.__array_interface__["data"][0])
        texels = np.arange(256 * 256 * 4, dtype=np.float32).reshape(256, 256, 4)
        t.write(texels)
        self.assertTrue(np.array_equal(a, texels), "the view sees the store: no copy was read")
        del t, b
        gc.collect()
        self.assertEqual(float(a[255, 255, 3]), 256 * 256 * 4 - 1.0)  # the view keeps it alive

    def test_a_write_rounds_to_the_texture_s_format(self):
        dev = vgpu_rt.Device("gf5700")
        t = dev.texture("half", 2, 1, 1, format="fp16")
        t.write(np.array([[0.1, 70000.0]], dtype=np.float32))
        self.assertEqual(t.format, "fp16")
        self.assertEqual(float(t.array[0, 0, 0]), float(np.float16(0.1)))
        self.assertEqual(float(t.array[0, 1, 0]), float("inf"))
        with self.assertRaisesRegex(ValueError, r"expected texels of shape \(1, 2, 1\)"):
            t.write(np.zeros((2, 2, 1), dtype=np.float32))
        with self.assertRaisesRegex(ValueError, "fp8"):
            dev.texture("x", 1, 1, format="fp8")

    def test_one_kernel_over_hand_made_texels_writes_every_channel_and_counts_its_pass(self):
        dev = vgpu_rt.Device("gf5700")
        k = vgpu_rt.kernels["accumulate samples"]  # sum.xyz + colour.xyz, sum.w + 1
        self.assertEqual(k.units, ["sample_sum", "result", "marks"])
        sums, colours = dev.texture("sum", 3, 1), dev.texture("colour", 3, 1)
        sums.write(np.array([[[1, 2, 3, 4], [0, 0, 0, 0], [-1, 0.5, 8, 1]]], dtype=np.float32))
        colours.write(np.array([[[0.5, 0.25, 0.125, 9], [1, 1, 1, 1], [1, -0.5, 0, 0]]],
                               dtype=np.float32))
        marks = dev.texture("marks", 3, 1)  # read only when gated (not by default)
        marks.write(np.full((1, 3, 4), 7.0, dtype=np.float32))
        out = dev.texture("out", 3, 1)
        r = dev.run(k, [sums, colours, marks], [out], query=True)
        want = np.array([[[1.5, 2.25, 3.125, 5], [1, 1, 1, 1], [0, 0, 8, 2]]], dtype=np.float32)
        self.assertTrue(np.array_equal(out.array, want), out.array)
        self.assertEqual(r["kernel"], "accumulate samples")
        self.assertEqual(r["size"], (3, 1))
        self.assertEqual(r["query"], 3)
        c = r["counters"]
        self.assertEqual(c["passes"], 1)
        self.assertEqual(c["fragments_shaded"], 3)
        self.assertEqual(c["texture_fetches"], 6)
        self.assertEqual(c["bytes_written"], 3 * 16)
        self.assertEqual(dev.totals["passes"], 1)

    def test_the_device_statistics_per_kernel_are_priced_as_a_frame_s(self):
        dev = vgpu_rt.Device("gf5700")
        a, b, out = dev.texture("a", 8, 4), dev.texture("b", 8, 4), dev.texture("out", 8, 4)
        acc = vgpu_rt.kernels["accumulate samples"]
        for _ in range(2):
            dev.run(acc, [a, b, a], [out])

        @vgpu_rt.kernel(units=["v"])
        def half(f):
            f.out[0] = f.fetch_own(0) * 0.5
        dev.run(half, [a], [out])
        s = dev.stats
        self.assertEqual([(k["name"], k["passes"]) for k in s["kernels"]],
                         [("accumulate samples", 2), ("half", 1)])
        self.assertEqual(s["totals"]["passes"], 3)
        # The counters are dev.totals'; the JSON adds the host's and the device's times.
        self.assertEqual({k: v for k, v in s["totals"].items() if k in dev.totals}, dev.totals)
        # The cost model prices the same figures from the C++ statistics and from the dict.
        for card in ("gf5700", "gf6600"):
            from_stats = vgpu_rt.predict(s, card)
            from_dict = vgpu_rt.predict(dict(s), card)
            self.assertGreater(from_stats["total_ms"], 0.0)
            self.assertAlmostEqual(from_stats["total_ms"], from_dict["total_ms"], places=9)

    def test_a_pass_with_the_wrong_targets_is_a_value_error(self):
        dev = vgpu_rt.Device("gf5700")
        t = dev.texture("t", 2, 2)
        with self.assertRaisesRegex(ValueError, "writes 1 target"):
            dev.run(vgpu_rt.kernels["accumulate samples"], [t, t, t], [t, t])
        with self.assertRaisesRegex(ValueError, "gf9999"):
            vgpu_rt.Device("gf9999")

    def test_what_the_device_refuses_is_a_value_error_and_the_device_runs_on(self):
        dev = vgpu_rt.Device("gf5700")
        k = vgpu_rt.kernels["accumulate samples"]
        t, out = dev.texture("t", 2, 2), dev.texture("out", 2, 2)
        with self.assertRaisesRegex(ValueError, "read/write hazard"):
            dev.run(k, [out, t, t], [out])
        with self.assertRaisesRegex(ValueError, "unit 0, which has no texture bound"):
            dev.run(k, [], [out])
        with self.assertRaisesRegex(ValueError, "texture unit 16 does not exist"):
            dev.run(k, [t] * 17, [out])
        with self.assertRaisesRegex(ValueError, "at most 4096x4096"):
            dev.texture("big", 8192, 1)
        self.assertEqual(dev.run(k, [t, t, t], [out])["counters"]["passes"], 1)


if __name__ == "__main__":
    unittest.main()
