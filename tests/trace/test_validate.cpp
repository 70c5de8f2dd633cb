// The one validation of a render's options (host/trace/validate.h): nothing refused at the
// defaults; each refused combination comes back as exactly one (option, value, why), in the
// command line's words; two refused options are two refusals; the scene's checks need the scene;
// and the stream tracer refuses what validate refuses.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "host/scene/scene.h"
#include "host/trace/validate.h"
#include "vgpu/device.h"
#include "vgpu/profile.h"

namespace {

using host::Refusal;
using host::RenderOptions;
using host::Request;

std::vector<Refusal> check(const RenderOptions& opt, const std::string& profile = "gf5700",
                           const Request* request = nullptr, const host::Scene* scene = nullptr) {
  return host::validate(opt, vgpu::profile(profile), request, scene);
}

const std::string kMrtLooping =
    "--mrt on with --kernels looping: the looping program already writes the traversal, voxel "
    "and hit targets in one pass; there are no separate passes left to fuse";

}  // namespace

TEST_CASE("the default options and the command line's defaults are refused nowhere") {
  CHECK(check({}).empty());
  const Request defaults;
  CHECK(check({}, "gf5700", &defaults).empty());
  for (const vgpu::Profile& p : vgpu::profiles()) CHECK(host::validate({}, p).empty());
}

TEST_CASE("each refused combination of options comes back as one option, value and reason") {
  RenderOptions mrt;
  mrt.mrt = true;
  CHECK(check(mrt) ==
        std::vector<Refusal>{{"--mrt", "on",
                              "--mrt on: program 'intersections + next triangle' writes 2 outputs; "
                              "profile gf5700 allows 1 (no multiple render targets)"}});
  CHECK(check(mrt, "gf6600").empty());

  RenderOptions looping = mrt;
  looping.looping = true;
  CHECK(check(looping, "gf6600") == std::vector<Refusal>{{"--mrt", "on", kMrtLooping}});

  RenderOptions dense;
  dense.beams = true;
  dense.adaptive = true;
  dense.spp = 16;
  CHECK(check(dense) ==
        std::vector<Refusal>{{"--beams", "on",
                              "--beams on: a dense stream's rays are packed, not laid out by tile: "
                              "add --compact off"}});
  dense.compact = false;
  CHECK(check(dense).empty());

  RenderOptions under;
  under.undersample = 2;
  under.spp = 4;
  CHECK(check(under) ==
        std::vector<Refusal>{
            {"--spp", "4", "--aa undersample:2 traces one ray per traced pixel; drop --spp 4"}});

  RenderOptions seven;
  seven.spp = 7;
  CHECK(check(seven) ==
        std::vector<Refusal>{{"--spp", "7",
                              "--spp: 7 samples per pixel: not a square (the samples form an n x "
                              "n grid: 1, 4, 9, 16, ..., 256)"}});

  RenderOptions gl;
  gl.device = "gl";
  gl.masks = true;
  CHECK(check(gl) == std::vector<Refusal>{
                         {"--masks", "on",
                          "--masks on needs stencil masks, which the gl device does not have"}});
}

TEST_CASE("the command line's own options are checked with the options it sets") {
  Request q;
  q.aa_criterion = "object";
  CHECK(check({}, "gf5700", &q) ==
        std::vector<Refusal>{{"--aa-criterion", "object",
                              "--aa-criterion object decides where adaptive sampling refines: add "
                              "--aa adaptive"}});

  Request cpu;
  cpu.engine = "cpu";
  cpu.predict = true;
  CHECK(check({}, "gf5700", &cpu) ==
        std::vector<Refusal>{{"--predict", "",
                              "--predict needs --engine stream (the cpu engine is a "
                              "double-precision reference without passes, lanes or masks)"}});

  Request frames;
  frames.frames = "0:1:3";
  frames.frame_count = 3;
  frames.files = {{"--out", "frame.png", false}};
  CHECK(check({}, "gf5700", &frames) ==
        std::vector<Refusal>{{"--out", "frame.png",
                              "--out frame.png: 3 frames need '#' in the file name for the frame "
                              "number (e.g. frame_####.png)"}});
  frames.files = {{"--out", "frame_#.png", true}};
  CHECK(check({}, "gf5700", &frames).empty());
}

TEST_CASE("two refused options are two refusals, in the command line's order") {
  RenderOptions opt;
  opt.undersample = 2;
  opt.spp = 4;
  opt.mrt = true;
  opt.looping = true;
  const std::vector<Refusal> r = check(opt, "gf6600");
  REQUIRE(r.size() == 2);
  CHECK(r[0].option == "--spp");
  CHECK(r[1] == Refusal{"--mrt", "on", kMrtLooping});
  CHECK(host::refusal_lines(r) == r[0].why + "\n" + r[1].why);

  // One option refused twice is one refusal, its first reason.
  RenderOptions beams;
  beams.beams = true;
  beams.beam_tile = 0;
  beams.adaptive = true;
  beams.spp = 4;
  beams.formats = host::Formats::all(vgpu::Format::fp16);
  const std::vector<Refusal> b = check(beams);
  REQUIRE(b.size() == 2);
  CHECK(b[0].option == "--beam-tile");
  CHECK(b[1].option == "--beams");
  CHECK(b[1].why.find("a dense stream's rays are packed") != std::string::npos);
}

TEST_CASE("the scene's checks need the scene: a glass scene refuses --trace-pixel") {
  host::Scene glass;
  host::Material m;
  m.transmission = 1.0f;
  glass.materials = {m};
  glass.material = {0};
  RenderOptions opt;
  opt.width = opt.height = 8;
  opt.trace_pixel = glm::ivec2(1, 1);
  CHECK(check(opt).empty());
  const std::vector<Refusal> r = check(opt, "gf5700", nullptr, &glass);
  REQUIRE(r.size() == 1);
  CHECK(r[0].option == "--trace-pixel");
  CHECK(r[0].why.find("ray streams (a glass scene or --ray-streams on)") != std::string::npos);
  opt.ray_streams = true;  // without glass, --ray-streams on alone
  CHECK(check(opt).size() == 1);
}

TEST_CASE("library callers get validate's refusals as the tracer throws them") {
  CHECK_NOTHROW(host::throw_refusals({}));
  RenderOptions seven;
  seven.spp = 7;
  CHECK_THROWS_AS(host::throw_refusals(check(seven)), std::invalid_argument);
  RenderOptions mrt;
  mrt.mrt = true;
  CHECK_THROWS_WITH_AS(host::throw_refusals(check(mrt)), check(mrt)[0].why.c_str(), vgpu::Error);
}
