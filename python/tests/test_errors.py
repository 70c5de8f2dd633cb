"""Bad input raises Python exceptions with the command line's messages; the interpreter lives on."""

import os
import tempfile
import unittest

import vgpu_rt


class ErrorTest(unittest.TestCase):
    def test_a_bad_value_is_a_value_error_with_the_command_line_s_message(self):
        with self.assertRaisesRegex(ValueError, r"--size: expected WxH \(e.g. 256x256\), got 'big'"):
            vgpu_rt.render("bunny", size="big")
        with self.assertRaisesRegex(ValueError, "--profile"):
            vgpu_rt.render("bunny", size="8x8", profile="gf9999")

    def test_a_bad_combination_is_a_value_error(self):
        with self.assertRaisesRegex(ValueError, "^--steps-per-pass needs --kernels looping$"):
            vgpu_rt.render("bunny", size="8x8", steps_per_pass=8)
        with self.assertRaisesRegex(ValueError, "--mrt"):
            vgpu_rt.render("bunny", size="8x8", mrt=True)  # gf5700 has one output

    def test_a_missing_scene_is_a_file_not_found_error_naming_it(self):
        with self.assertRaisesRegex(FileNotFoundError,
                                    "^no_such_scene.gltf: no such file or scene in .*scenes "):
            vgpu_rt.render("no_such_scene.gltf", size="8x8")

    def test_an_unreadable_scene_file_is_a_value_error_naming_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "broken.gltf")
            with open(path, "w") as f:
                f.write("{ not json")
            with self.assertRaises(ValueError) as caught:
                vgpu_rt.render(path, size="8x8")
            self.assertIn("broken.gltf", str(caught.exception))
            self.assertNotIn("\n", str(caught.exception))

    def test_an_unknown_option_is_a_type_error_as_for_any_python_call(self):
        with self.assertRaisesRegex(TypeError, "unexpected keyword argument 'sizes'"):
            vgpu_rt.render("bunny", sizes="8x8")

    def test_nothing_is_written_when_the_options_are_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "x.png")
            with self.assertRaises(ValueError):
                vgpu_rt.render("bunny", size="8x8", out=out, steps_per_pass=8)
            self.assertEqual(os.listdir(tmp), [])

    def test_after_errors_the_module_still_renders(self):
        for bad in ({"size": "0x0"}, {"bounces": -1}, {"lanes": 3}):
            with self.assertRaises(ValueError):
                vgpu_rt.render("bunny", **bad)
        self.assertEqual(vgpu_rt.render("bunny", size="8x8").image.shape, (8, 8, 3))

    def test_predict_refuses_an_unknown_profile_and_a_dict_without_statistics(self):
        f = vgpu_rt.render("bunny", size="8x8", bounces=0)
        with self.assertRaisesRegex(ValueError, "gf9999"):
            vgpu_rt.predict(f.stats, "gf9999")
        with self.assertRaisesRegex(ValueError, "no 'totals' and 'kernels'"):
            vgpu_rt.predict({"scene": "bunny"}, "gf5700")


if __name__ == "__main__":
    unittest.main()
