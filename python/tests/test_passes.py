"""vgpu_rt.passes: a frame pass by pass, stopped and resumed, agrees with the whole frame."""

import base64
import csv
import gc
import gzip
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

import vgpu_rt

CLI = os.environ.get("VGPU_RT_CLI", "")
OPTIONS = dict(size="16x16", bounces=1)


def report_data(path):
    """The data an HTML report (`vgpu-rt render --report`) carries, as a dict."""
    with open(path) as f:
        page = f.read()
    tag = '<script id="report-data" type="application/json">'
    start = page.index(tag) + len(tag)
    return json.loads(page[start:page.index("</script>", start)])


def unpack(text, dtype):
    """One of the report's arrays: gzip, then base64 (host/report/report.cpp's pack)."""
    return np.frombuffer(gzip.decompress(base64.b64decode(text)), dtype)


class PassesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.whole = vgpu_rt.render("bunny", **OPTIONS)
        cls.steps = vgpu_rt.passes("bunny", **OPTIONS)
        cls.seen = list(cls.steps)

    def test_every_pass_is_seen_once_in_order(self):
        totals = self.whole.stats["totals"]
        self.assertEqual(len(self.seen), totals["passes"])
        self.assertEqual([p.index for p in self.seen], list(range(len(self.seen))))
        self.assertEqual(self.seen[0].kernel, "generate rays")
        self.assertEqual(sum(p.counters["passes"] for p in self.seen), totals["passes"])
        self.assertEqual(max(p.iteration for p in self.seen), self.whole.stats["iterations"])

    def test_the_occlusion_query_counts_are_shown_at_their_passes(self):
        counted = [p for p in self.seen if p.query is not None]
        self.assertEqual(len(counted), self.whole.stats["totals"]["queries"])
        for p in counted:
            self.assertLessEqual(p.query, 16 * 16)
        self.assertEqual(counted[-1].frame_totals["query_readbacks"],
                         self.whole.stats["totals"]["query_readbacks"])

    @unittest.skipUnless(CLI, "VGPU_RT_CLI names the vgpu-rt executable")
    def test_each_pass_is_the_command_line_s_stats_csv_row(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "passes.csv")
            subprocess.run([CLI, "render", "bunny", "--size", "16x16", "--bounces", "1", "--stats",
                            "none", "--quiet", "--stats-csv", path], check=True)
            with open(path) as f:
                rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), len(self.seen))
        for row, p in zip(rows, self.seen):
            where = f"pass {p.index} {p.kernel}"
            self.assertEqual(row["kernel"], p.kernel, where)
            self.assertEqual(int(row["iteration"]), p.iteration, where)
            self.assertEqual(row["trace_kind"] or None, p.trace, where)
            self.assertEqual(row["target"], p.target_name, where)
            for key in ("fragments_shaded", "instructions", "texture_fetches", "bytes_written"):
                self.assertEqual(int(row[key]), p.counters[key], f"{where} {key}")
            self.assertEqual(int(row["query_result"]) if row["query_result"] else None, p.query,
                             where)

    def test_each_pass_shows_its_target_after_the_pass(self):
        first = self.seen[0]  # generate rays: unit directions
        self.assertEqual(first.target.shape, (16, 16, first.target.shape[2]))
        norms = np.linalg.norm(first.target[:, :, :3], axis=2)
        self.assertTrue(np.allclose(norms, 1.0, atol=1e-5), norms)

    @unittest.skipUnless(CLI, "VGPU_RT_CLI names the vgpu-rt executable")
    def test_every_pass_s_target_holds_what_the_command_line_s_report_kept_of_it(self):
        # A 24x20 frame (not square: rows and columns cannot trade places unseen) with masks:
        # every pass's target is the frame's size with the report's channels, and the report
        # keeps the state after every pass of the pixels whose x and y are multiples of 8 (nine
        # of them), for each pass they took part in (its work mask holds them) that writes
        # state: each must be that texel of the pass's target, bit for bit.
        w, h = 24, 20
        seen = list(vgpu_rt.passes("bunny", size=(w, h), bounces=1, masks=True))
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "report.html")
            subprocess.run([CLI, "render", "bunny", "--size", f"{w}x{h}", "--bounces", "1",
                            "--masks", "on", "--stats", "none", "--quiet", "--report", path],
                           check=True)
            d = report_data(path)
        cols = {name: unpack(text, np.float64) for name, text in d["passes"].items()}
        self.assertEqual(len(cols["kernel"]), len(seen))
        # The work masks: each stored XOR the one before it, a bit per pixel, row by row.
        chain = unpack(d["masks"], np.uint8).reshape(d["mask_count"], (w * h + 7) // 8)
        bits = np.unpackbits(np.bitwise_xor.accumulate(chain, axis=0), axis=1, bitorder="little")
        masks = bits[:, :w * h].reshape(-1, h, w).astype(bool)
        for i, p in enumerate(seen):
            self.assertEqual(d["kernel_names"][int(cols["kernel"][i])], p.kernel, i)
            self.assertEqual(d["target_names"][int(cols["target"][i])], p.target_name, i)
            self.assertEqual(p.target.shape, (h, w, int(cols["channels"][i])), i)
            if p.work is not None:  # the stencil the pass ran under is the report's work mask
                self.assertTrue(np.array_equal(p.work, masks[int(cols["work"][i])]), i)
        kept = d["history"]["pixels"]
        self.assertEqual(len(kept), 9)
        checked = 0
        for (x, y), packed in zip(kept, d["history"]["states"]):
            states = unpack(packed, np.float32)
            at = 0
            for i, p in enumerate(seen):
                rows, columns, channels = p.target.shape
                mask = int(cols["work"][i])
                if not cols["prints"][i] or x >= columns or y >= rows:
                    continue
                if mask >= 0 and not masks[mask, y, x]:
                    continue
                self.assertEqual(p.target[y, x].tobytes(), states[at:at + channels].tobytes(),
                                 f"pass {i} {p.kernel}, pixel {x},{y}")
                at += channels
                checked += 1
            self.assertEqual(at, len(states), f"pixel {x},{y}")
        self.assertGreater(checked, 9 * 20)  # every kept pixel in dozens of passes

    def test_the_frame_after_its_passes_is_the_whole_frame(self):
        f = self.steps.frame
        self.assertTrue(np.array_equal(f.image, self.whole.image))
        self.assertTrue(np.array_equal(f.hit, self.whole.hit))
        self.assertEqual(f.stats["totals"]["passes"], self.whole.stats["totals"]["passes"])

    def test_a_frame_stopped_and_resumed_gives_the_same_passes(self):
        steps = vgpu_rt.passes("bunny", **OPTIONS)
        head = [next(steps) for _ in range(5)]
        self.assertIsNone(steps.frame, "not finished")
        rest = list(steps)
        self.assertEqual([p.kernel for p in head + rest], [p.kernel for p in self.seen])
        self.assertEqual([p.query for p in head + rest], [p.query for p in self.seen])

    def test_the_pixels_a_counting_pass_wrote_are_its_query_count(self):
        counted = [p for p in self.seen if p.written is not None]
        self.assertGreater(len(counted), 0)
        for p in counted:
            self.assertEqual(p.written.shape, (16, 16))
            self.assertEqual(p.written.dtype, np.bool_)
            self.assertEqual(int(p.written.sum()), p.query, f"pass {p.index} {p.kernel}")
        # The host steers by those counts: every pass that runs under a stencil runs under one
        # a counting pass wrote before it (the rays walking, or the rays with triangles to test).
        written = set()
        for p in self.seen:
            if p.work is not None:
                self.assertIn(p.work.tobytes(), written, f"pass {p.index} {p.kernel}")
            if p.written is not None:
                written.add(p.written.tobytes())

    def test_with_masks_each_pass_shades_the_pixels_its_stencil_marks(self):
        seen = [p for p in vgpu_rt.passes("bunny", size="16x16", bounces=1, masks="on")
                if p.work is not None]
        self.assertGreater(len(seen), 0)
        for p in seen:
            self.assertEqual(int(p.work.sum()), p.counters["fragments_shaded"],
                             f"pass {p.index} {p.kernel}")

    def test_a_looping_pass_shows_each_pixel_s_loop_iterations(self):
        loops = [p for p in vgpu_rt.passes("bunny", size="16x16", bounces=0, kernels="looping",
                                           profile="gf6600") if p.iterations is not None]
        self.assertGreater(len(loops), 0)
        for p in loops:
            self.assertEqual(p.iterations.shape, (16, 16))
            self.assertEqual(int(p.iterations.sum()), p.counters["loop_iterations"])
            self.assertEqual(int(p.iterations.max()), p.counters["loop_span_iterations"])
            self.assertFalse(p.iterations[~p.work].any(), "no loop where the stencil is off")

    def test_a_frame_left_half_way_is_let_go(self):
        steps = vgpu_rt.passes("bunny", **OPTIONS)
        next(steps)
        del steps
        gc.collect()  # the worker runs the frame out and is joined
        self.assertEqual(len(list(vgpu_rt.passes("bunny", size="8x8", bounces=0))) > 0, True)

    def test_what_passes_cannot_follow_is_refused(self):
        with self.assertRaisesRegex(ValueError, "follows one frame"):
            vgpu_rt.passes("hop", size="8x8", frames="0:1:2")
        with self.assertRaisesRegex(ValueError, "needs --engine stream"):
            vgpu_rt.passes("bunny", size="8x8", engine="cpu")
        with self.assertRaises(FileNotFoundError):
            vgpu_rt.passes("nowhere.glb")


if __name__ == "__main__":
    unittest.main()
