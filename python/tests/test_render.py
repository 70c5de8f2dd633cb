"""vgpu_rt.render and vgpu_rt.scenes against the command line (the same frame's --stats-json)."""

import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import vgpu_rt

CLI = os.environ.get("VGPU_RT_CLI", "")
# Fields that time the host or describe this run's machine: they differ between two runs.
TIMED = {"init_ms", "grid_build_ms", "render_ms", "host_ms", "build_ms", "probe_ms", "threads",
         "peak_rss_bytes", "memory"}


def untimed(value):
    """The statistics without their wall-clock fields."""
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if k not in TIMED}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


class RenderTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.frame = vgpu_rt.render("bunny", size="32x24", bounces=1)

    def test_the_image_and_aovs_are_float32_arrays_of_the_frame_s_shape(self):
        f = self.frame
        self.assertEqual(f.image.shape, (24, 32, 3))
        self.assertEqual(f.depth.shape, (24, 32))
        self.assertEqual(f.hit.shape, (24, 32))
        for a in (f.image, f.depth, f.hit):
            self.assertEqual(a.dtype, np.float32)
            self.assertTrue(a.flags["C_CONTIGUOUS"])

    def test_the_aovs_agree_a_missed_pixel_has_depth_0_and_hit_minus_1(self):
        f = self.frame
        missed = f.hit < 0
        self.assertTrue(missed.any() and (~missed).any(), "the bunny covers part of the frame")
        self.assertTrue(np.all(f.depth[missed] == 0))
        self.assertTrue(np.all(f.depth[~missed] > 0))
        self.assertTrue(np.all(f.hit[~missed] < f.stats["input_triangles"]))
        self.assertGreater(float(f.image[~missed].max()), 0.0)

    def test_a_list_option_goes_to_the_command_line_as_its_comma_separated_word(self):
        f = vgpu_rt.render("bunny-refl", size=(16, 16), bounces=0, aa="adaptive", spp=16,
                           aa_budget=(25, 20))
        sampling = f.stats["sampling"]
        self.assertEqual(sampling["criterion"], "budget")
        self.assertEqual(sampling["budget_shares"], [0.25, 0.2])
        self.assertEqual(len(sampling["budget_levels"]), 2)

    @unittest.skipUnless(CLI, "VGPU_RT_CLI names the vgpu-rt executable")
    def test_the_stats_are_the_dict_the_command_line_writes_for_the_same_frame(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "s.json")
            subprocess.run([CLI, "render", "bunny", "--size", "32x24", "--bounces", "1", "--stats",
                            "none", "--quiet", "--stats-json", path], check=True)
            with open(path) as f:
                cli = json.load(f)
        ours = self.frame.stats
        self.assertEqual(list(ours.keys()), list(cli.keys()))
        self.assertEqual(untimed(dict(ours)), untimed(cli))

    def test_options_take_the_command_line_s_names_and_python_values(self):
        f = vgpu_rt.render("bunny", size=(16, 8), bounces=0, shadows=False, profile="gf6600",
                           masks=True, texture_filter="nearest")
        self.assertEqual(f.image.shape, (8, 16, 3))
        s = f.stats
        self.assertEqual(s["size"], [16, 8])
        self.assertEqual(s["iterations"], 1)
        self.assertEqual(s["profile"], "gf6600")
        self.assertIs(s["shadows"], False)
        self.assertIs(s["masks"], True)

    def test_sampling_and_animation_time_reach_the_frame(self):
        f = vgpu_rt.render("hop", size="16x16", bounces=0, spp=4, time=0.25)
        self.assertEqual(f.stats["sampling"]["spp"], 4)
        self.assertEqual(f.stats["sampling"]["mode"], "uniform")
        self.assertEqual(f.stats["time"], 0.25)
        a = vgpu_rt.render("bunny", size="16x16", bounces=0, spp=4, aa="adaptive")
        self.assertEqual(a.stats["sampling"]["mode"], "adaptive")

    def test_render_prints_nothing_unless_asked(self):
        # The command line prints its table on stdout and progress on stderr; Python returns them.
        code = "import vgpu_rt; vgpu_rt.render('bunny', size='8x8', bounces=0)"
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        self.assertEqual((r.returncode, r.stdout, r.stderr), (0, "", ""))
        code = "import vgpu_rt; vgpu_rt.render('bunny', size='8x8', bounces=0, stats='json')"
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        self.assertEqual(json.loads(r.stdout)["size"], [8, 8])

    def test_scenes_lists_the_bundled_files(self):
        s = vgpu_rt.scenes()
        self.assertIn("bunny", s)
        self.assertIn("hop", s)
        for path in s.values():
            self.assertTrue(os.path.isfile(path), path)

    def test_render_s_help_lists_every_option_with_its_default(self):
        doc = vgpu_rt.render.__doc__
        for line in ("texture_filter:", "steps_per_pass:", "(default 256x256)", "(default gf5700)"):
            self.assertIn(line, doc)

    def test_the_type_stub_names_every_render_option(self):
        stub = os.path.join(os.path.dirname(vgpu_rt.__file__), "__init__.pyi")
        with open(stub) as f:
            text = f.read()
        signature = text[text.index("def render("):text.index(") -> Frame")]
        for name in vgpu_rt._OPTIONS:
            self.assertIn(f"    {name.replace('-', '_')}: ", signature, name)


if __name__ == "__main__":
    unittest.main()
