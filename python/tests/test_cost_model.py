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

    def test_a_profile_s_fixed_costs_are_the_ones_the_model_charges(self):
        totals = self.frame.stats["totals"]
        for p in vgpu_rt.profiles():
            got = vgpu_rt.predict(self.frame, p["name"])
            self.assertAlmostEqual(got["per_pass_ms"], totals["passes"] * p["pass_us"] / 1e3,
                                   places=6, msg=p["name"])
            self.assertAlmostEqual(got["readback_ms"],
                                   totals["query_readbacks"] * p["readback_us"] / 1e3, places=6,
                                   msg=p["name"])
            self.assertIsInstance(p["dynamic_branching"], bool)
        by_name = {p["name"]: p for p in vgpu_rt.profiles()}
        self.assertFalse(by_name["gf5700"]["dynamic_branching"])  # fp30: no branches
        self.assertTrue(by_name["gf6600"]["dynamic_branching"])  # fp40

    def test_a_render_s_stats_are_priced_exactly_as_the_command_line_prices_them(self):
        s = self.frame.stats
        for name in s["predicted_ms"]:
            got = vgpu_rt.predict(self.frame, name)
            self.assertEqual(got["total_ms"], s["predicted_ms"][name], name)
            for key, ms in s["predicted_breakdown"][name].items():
                self.assertEqual(got[key], ms, f"{name} {key}")

    def test_a_plain_stats_dict_is_priced_as_the_command_line_prices_it(self):
        plain = json.loads(json.dumps(self.frame.stats))  # as read from a --stats-json file
        self.assertNotIsInstance(plain, vgpu_rt.Stats)
        for name in plain["predicted_ms"]:
            got = vgpu_rt.predict(plain, name)
            self.assertEqual(got["total_ms"], plain["predicted_ms"][name], name)
            for key, ms in plain["predicted_breakdown"][name].items():
                self.assertEqual(got[key], ms, f"{name} {key}")
        self.assertGreater(plain["predicted_breakdown"]["h200"]["download_ms"], 0)

if __name__ == "__main__":
    unittest.main()
