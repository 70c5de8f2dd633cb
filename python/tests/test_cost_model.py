"""vgpu_rt.predict and vgpu_rt.profiles price a frame as the command line does."""

import json
import unittest

import vgpu_rt


class CostModelTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.frame = vgpu_rt.render("bunny", size="32x32", bounces=1)

    def test_profiles_are_the_ones_the_stats_are_priced_on(self):
        names = [p["name"] for p in vgpu_rt.profiles()]
        self.assertEqual(names, list(self.frame.stats["predicted_ms"].keys()))
        for p in vgpu_rt.profiles():
            self.assertGreater(p["core_mhz"], 0)

    def test_a_render_s_stats_are_priced_exactly_as_the_command_line_prices_them(self):
        s = self.frame.stats
        for name in s["predicted_ms"]:
            got = vgpu_rt.predict(self.frame, name)
            self.assertEqual(got["total_ms"], s["predicted_ms"][name], name)
            for key, ms in s["predicted_breakdown"][name].items():
                self.assertEqual(got[key], ms, f"{name} {key}")

    def test_a_plain_stats_dict_is_priced_from_its_kernels_totals(self):
        plain = json.loads(json.dumps(self.frame.stats))  # as read from a --stats-json file
        exact = vgpu_rt.predict(self.frame.stats, "gf5700")
        spread = vgpu_rt.predict(plain, "gf5700")
        # The frame-wide terms depend on the totals alone: equal. The pass work is each kernel's
        # passes taken as alike: at most the pass-by-pass figure (a max of sums <= sum of maxes).
        for key in ("per_pass_ms", "program_load_ms", "readback_ms", "download_ms"):
            self.assertAlmostEqual(spread[key], exact[key], places=9, msg=key)
        work = lambda b: b["arithmetic_ms"] + b["texture_ms"] + b["memory_ms"]
        self.assertGreater(work(spread), 0.0)
        self.assertLessEqual(work(spread), work(exact) * (1 + 1e-9))


if __name__ == "__main__":
    unittest.main()
