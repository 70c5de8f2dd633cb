"""vgpu_rt.render's arrays against the files the command line writes for the same frame: the
image (an EXR bit for bit, a PNG after its 8-bit rounding), the AOVs given as a list, and the
animated scene hop posed at two times (tests/exr.py reads the EXR files)."""

import os
import subprocess
import tempfile
import unittest

import numpy as np
from PIL import Image

import exr
import vgpu_rt

CLI = os.environ.get("VGPU_RT_CLI", "")
# Not square, so that rows and columns cannot trade places unseen; one reflection.
SIZE, BOUNCES = (40, 36), 1


def cli_render(scene, *args):
    """`vgpu-rt render SCENE` at SIZE with BOUNCES and `args`, quietly."""
    subprocess.run([CLI, "render", scene, "--size", "{}x{}".format(*SIZE), "--bounces",
                    str(BOUNCES), "--stats", "none", "--quiet", *args], check=True)


def exr_rgb(path):
    c = exr.read(path)
    return np.stack([c["R"], c["G"], c["B"]], axis=-1)


def same_bits(a, b):
    """The same shape and the same float32 bits in every element."""
    a, b = np.asarray(a, np.float32), np.asarray(b, np.float32)
    return a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


class ImagesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.frame = vgpu_rt.render("bunny", size=SIZE, bounces=BOUNCES)

    @unittest.skipUnless(CLI, "VGPU_RT_CLI names the vgpu-rt executable")
    def test_the_image_is_the_command_line_s_exr_bit_for_bit_and_its_png_after_rounding(self):
        image = self.frame.image
        self.assertEqual(image.shape, (SIZE[1], SIZE[0], 3))
        with tempfile.TemporaryDirectory() as tmp:
            cli_render("bunny", "--out", os.path.join(tmp, "x.exr"))
            cli_render("bunny", "--out", os.path.join(tmp, "x.png"))
            from_exr = exr_rgb(os.path.join(tmp, "x.exr"))
            with Image.open(os.path.join(tmp, "x.png")) as png:
                self.assertEqual(png.mode, "RGB")
                from_png = np.asarray(png)
        self.assertTrue(same_bits(image, from_exr),
                        f"{int((image != from_exr).any(axis=2).sum())} pixels differ")
        # The PNG holds the linear colour clamped to [0, 1], 8 bits, rounded to nearest (as the
        # report's copy of it, host/report/report.cpp).
        rounded = np.floor(np.clip(image, 0.0, 1.0) * np.float32(255) + np.float32(0.5))
        self.assertTrue(np.array_equal(from_png, rounded.astype(np.uint8)))
        # A frame where all of that matters: colours between the 8-bit steps, some past 1, and
        # rows that differ from the rows opposite them.
        self.assertTrue(((image > 0.01) & (image < 0.99)).any())
        self.assertTrue((image > 1.0).any())
        self.assertFalse(np.array_equal(image, image[::-1]))

    def test_the_aov_list_form_writes_every_aov_it_names(self):
        with tempfile.TemporaryDirectory() as tmp:
            depth, hit = os.path.join(tmp, "depth.exr"), os.path.join(tmp, "hit.exr")
            for form in (list, tuple):
                f = vgpu_rt.render("bunny", size=SIZE, bounces=BOUNCES,
                                   aov=form([f"depth={depth}", f"hit={hit}"]))
                self.assertTrue(same_bits(exr.read(depth)["Y"], f.depth), form)
                self.assertTrue(same_bits(exr.read(hit)["Y"], f.hit), form)
                os.remove(depth)
                os.remove(hit)
            # Not a frame of misses alone: the two AOVs hold something to compare.
            self.assertTrue((f.hit >= 0).any() and (f.hit < 0).any())

    @unittest.skipUnless(CLI, "VGPU_RT_CLI names the vgpu-rt executable")
    def test_time_poses_the_animated_scene_as_the_command_line_s_time_does(self):
        early = vgpu_rt.render("hop", size=SIZE, bounces=BOUNCES, time=0.5)
        late = vgpu_rt.render("hop", size=SIZE, bounces=BOUNCES, time=1.5)
        self.assertEqual((early.stats["time"], late.stats["time"]), (0.5, 1.5))
        # hop's ball is elsewhere at 1.5 s than at 0.5 s: some pixels see other triangles.
        self.assertGreater(int((early.hit != late.hit).sum()), 0)
        self.assertFalse(np.array_equal(early.image, late.image))
        with tempfile.TemporaryDirectory() as tmp:
            cli_render("hop", "--time", "1.5", "--out", os.path.join(tmp, "late.exr"),
                       "--aov", "hit=" + os.path.join(tmp, "hit.exr"))
            self.assertTrue(same_bits(late.image, exr_rgb(os.path.join(tmp, "late.exr"))))
            self.assertTrue(same_bits(late.hit, exr.read(os.path.join(tmp, "hit.exr"))["Y"]))


if __name__ == "__main__":
    unittest.main()
