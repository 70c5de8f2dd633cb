// The profiles' limits: every violation is rejected with a vgpu::Error whose message names the
// program (or the texture) and the rule it broke.
#include <doctest/doctest.h>

#include <array>
#include <stdexcept>

#include "helpers.h"
#include "vgpu/vgpu.h"

using namespace vgpu;
using doctest::Contains;

namespace {

struct TwoOutputs {
  static constexpr const char* name = "two outputs";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 2;
  template <class L>
  void operator()(Fragments<L>& f) const {
    const Vec4<typename L::F> v = f.fetch_own(0);
    f.out(0) = v;
    f.out(1) = {v.w, v.z, v.y, v.x};
  }
};

struct ReadUnit3 {
  static constexpr const char* name = "read unit 3";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    f.out(0) = f.fetch_own(3);
  }
};

// A constant loop of `ops` additions: ops instructions, no fetch.
struct LongLoop {
  static constexpr const char* name = "long loop";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  int ops = 1100;
  template <class L>
  void operator()(Fragments<L>& f) const {
    using F = typename L::F;
    F s = f.x;
    for (int i = 0; i < ops; ++i) s = s + F(1.0f);
    f.out(0) = {s, s, s, s};
  }
};

struct NoPassthrough {
  static constexpr const char* name = "no passthrough";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  template <class L>
  void operator()(Fragments<L>& f) const {
    f.out(0) = f.fetch_own(0);
  }
};

struct WithPassthrough {
  static constexpr const char* name = "with passthrough";
  static constexpr const char* paper_name = "-";
  static constexpr int outputs = 1;
  static constexpr std::array<int, 1> passthrough{0};
  template <class L>
  void operator()(Fragments<L>& f) const {
    f.out(0) = f.fetch_own(0);
  }
};

}  // namespace

TEST_CASE("two outputs are rejected on gf5700 and allowed on gf6600") {
  KernelProgram<TwoOutputs> two;
  {
    Gpu gpu(profile("gf5700"), 1);
    Texture in = gpu.make_texture("in", 8, 8, 4), o0 = gpu.make_texture("o0", 8, 8, 4),
            o1 = gpu.make_texture("o1", 8, 8, 4);
    gpu.use_program(two);
    gpu.bind_texture(0, in);
    gpu.set_targets({&o0, &o1});
    CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'two outputs' writes 2 outputs"), Error);
    CHECK_THROWS_WITH_AS(gpu.draw(), Contains("gf5700 allows 1"), Error);
    CHECK(gpu.stats().totals.passes == 0);
  }
  Gpu gpu(profile("gf6600"), 1);
  Texture in = gpu.make_texture("in", 8, 8, 4), o0 = gpu.make_texture("o0", 8, 8, 4),
          o1 = gpu.make_texture("o1", 8, 8, 4);
  in.set(3, 4, 0, 5.0f);
  in.set(3, 4, 3, 7.0f);
  gpu.use_program(two);
  gpu.bind_texture(0, in);
  gpu.set_targets({&o0, &o1});
  const PassRecord& rec = gpu.draw();
  CHECK(rec.counters.bytes_written == 64 * 2 * 16);
  CHECK(o0.get(3, 4, 0) == 5.0f);
  CHECK(o1.get(3, 4, 0) == 7.0f);
  CHECK(o1.get(3, 4, 3) == 5.0f);
}

TEST_CASE("a program may not read a texture it renders to") {
  Gpu gpu(profile("gf6600"), 1);
  Texture a = gpu.make_texture("state a", 8, 8, 4), b = gpu.make_texture("state b", 8, 8, 4);
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(copy);
  gpu.bind_texture(0, a);
  gpu.set_targets({&a});
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'copy' reads texture 'state a' (unit 0)"),
                       Error);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("ping-pong"), Error);
  // Any unit counts, also one the program does not fetch from.
  gpu.bind_texture(0, b);
  gpu.bind_texture(5, a);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("'state a' (unit 5)"), Error);
  gpu.unbind_textures();
  gpu.bind_texture(0, b);
  CHECK_NOTHROW(gpu.draw());  // ping-pong: read b, write a
}

TEST_CASE("textures larger than the profile's maximum size are rejected") {
  Gpu gpu(profile("gf5700"), 1);
  CHECK_THROWS_WITH_AS(gpu.make_texture("huge", 4097, 1, 1),
                       Contains("texture 'huge' is 4097x1 texels; profile gf5700 allows at most "
                                "4096x4096"),
                       Error);
  CHECK_THROWS_WITH_AS(gpu.make_texture("tall", 1, 4097, 1), Contains("'tall'"), Error);
  CHECK_THROWS_WITH_AS(gpu.make_texture("empty", 0, 4, 1), Contains("'empty' has an empty size"),
                       Error);
  CHECK_NOTHROW(gpu.make_texture("edge", 4096, 1, 1));
  CHECK_NOTHROW(Gpu(profile("rtx4090"), 1).make_texture("big", 4097, 1, 1));
  // A texture made elsewhere is checked when it is bound or rendered to.
  Texture big("big", 4097, 1, 1);
  CHECK_THROWS_WITH_AS(gpu.bind_texture(0, big), Contains("'big'"), Error);
  CHECK_THROWS_WITH_AS(gpu.set_targets({&big}), Contains("'big'"), Error);
}

TEST_CASE("fetching from a texture unit with nothing bound is rejected") {
  Gpu gpu(profile("gf6600"), 1);
  Texture in = gpu.make_texture("in", 8, 8, 4), out = gpu.make_texture("out", 8, 8, 4);
  KernelProgram<ReadUnit3> k;
  gpu.use_program(k);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  CHECK_THROWS_WITH_AS(gpu.draw(),
                       Contains("program 'read unit 3' fetches from texture unit 3, which has no "
                                "texture bound"),
                       Error);
  gpu.bind_texture(3, in);
  CHECK_NOTHROW(gpu.draw());
  CHECK_THROWS_WITH_AS(gpu.bind_texture(16, in), Contains("texture unit 16 does not exist"), Error);
  CHECK_THROWS_AS(gpu.bind_texture(-1, in), Error);
}

TEST_CASE("a program longer than the profile's instruction limit is rejected") {
  KernelProgram<LongLoop> loop;
  CHECK(loop.analyze().instructions == 1100);
  Gpu fx(profile("gf5700"), 1);
  Texture out = fx.make_texture("out", 4, 4, 4);
  fx.use_program(loop);
  fx.set_targets({&out});
  CHECK_THROWS_WITH_AS(fx.draw(),
                       Contains("program 'long loop' has 1100 instructions; profile gf5700 "
                                "allows 1024"),
                       Error);
  loop.kernel.ops = 1024;  // a uniform: the limit applies to the count at draw time
  CHECK_NOTHROW(fx.draw());
  loop.kernel.ops = 1025;
  CHECK_THROWS_WITH_AS(fx.draw(), Contains("1025 instructions"), Error);
  Gpu g6(profile("gf6600"), 1);
  Texture out6 = g6.make_texture("out", 4, 4, 4);
  loop.kernel.ops = 1100;
  g6.use_program(loop);
  g6.set_targets({&out6});
  CHECK_NOTHROW(g6.draw());
}

TEST_CASE("a draw needs a program and render targets matching its outputs") {
  Gpu gpu(profile("gf6600"), 1);
  Texture in = gpu.make_texture("in", 8, 8, 4), o0 = gpu.make_texture("o0", 8, 8, 4),
          small = gpu.make_texture("small", 4, 8, 4);
  CHECK_THROWS_WITH_AS(gpu.draw(Rect{0, 0, 8, 8}), Contains("no program bound"), Error);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("no render target"), Error);
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(copy);
  gpu.bind_texture(0, in);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'copy': draw with no render target set"),
                       Error);
  CHECK_THROWS_WITH_AS(gpu.draw(Rect{0, 0, 8, 8}),
                       Contains("program 'copy' writes 1 outputs but 0 render targets are set"),
                       Error);
  KernelProgram<TwoOutputs> two;
  gpu.use_program(two);
  gpu.set_targets({&o0});
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'two outputs' writes 2 outputs but 1"), Error);
  gpu.set_targets({&o0, &small});
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'two outputs': render targets differ in size"),
                       Error);
}

TEST_CASE("a rectangle outside the render target is rejected") {
  Gpu gpu(profile("gf5700"), 1);
  Texture in = gpu.make_texture("in", 8, 8, 4), out = gpu.make_texture("out", 8, 8, 4);
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(copy);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  for (const Rect& r : {Rect{-1, 0, 8, 8}, Rect{0, -1, 8, 8}, Rect{0, 0, 9, 8}, Rect{0, 0, 8, 9},
                        Rect{5, 0, 4, 8}, Rect{0, 5, 8, 4}}) {
    CAPTURE(r.x0);
    CAPTURE(r.y0);
    CAPTURE(r.x1);
    CAPTURE(r.y1);
    CHECK_THROWS_WITH_AS(
        gpu.draw(r), Contains("program 'copy': drawn rectangle outside the render target"), Error);
  }
  CHECK(gpu.draw(Rect{8, 8, 8, 8}).counters.fragments_launched == 0);  // empty, not outside
  CHECK(gpu.draw(Rect{0, 0, 8, 8}).counters.fragments_launched == 64);
}

TEST_CASE("masks must match the render target's size") {
  Gpu gpu(profile("gf5700"), 1);
  Texture in = gpu.make_texture("in", 8, 8, 4), out = gpu.make_texture("out", 8, 8, 4);
  KernelProgram<vgpu_test::Copy> copy;
  gpu.use_program(copy);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  Stencil wrong(8, 7);
  gpu.set_stencil_test(&wrong);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'copy': stencil size differs"), Error);
  gpu.set_stencil_test(nullptr);
  gpu.set_stencil_write(&wrong);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'copy': stencil size differs"), Error);
  gpu.set_stencil_write(nullptr);
  KernelProgram<WithPassthrough> pass;
  gpu.use_program(pass);
  gpu.set_work_mask(&wrong);
  CHECK_THROWS_WITH_AS(gpu.draw(), Contains("program 'with passthrough': work mask size differs"),
                       Error);
}

TEST_CASE("a work mask needs a program that declares its passthrough") {
  Gpu gpu(profile("gf6600"), 1);
  Texture in = gpu.make_texture("in", 8, 8, 4), out = gpu.make_texture("out", 8, 8, 4);
  Texture narrow = gpu.make_texture("narrow", 8, 8, 2);
  Stencil work(8, 8, 1);
  KernelProgram<NoPassthrough> none;
  gpu.use_program(none);
  gpu.bind_texture(0, in);
  gpu.set_targets({&out});
  gpu.set_work_mask(&work);
  CHECK_THROWS_WITH_AS(gpu.draw(),
                       Contains("program 'no passthrough' declares no passthrough, so it cannot "
                                "skip idle fragments"),
                       Error);
  KernelProgram<WithPassthrough> with;
  gpu.use_program(with);
  CHECK_NOTHROW(gpu.draw());
  gpu.bind_texture(0, narrow);  // the passthrough unit must hold the target's shape
  CHECK_THROWS_WITH_AS(gpu.draw(),
                       Contains("program 'with passthrough': passthrough unit 0 does not hold a "
                                "texture shaped like render target 0"),
                       Error);
  gpu.set_work_mask(nullptr);
  CHECK_NOTHROW(gpu.draw());
}

TEST_CASE("queries must be begun before they are ended, and not twice") {
  Gpu gpu(profile("gf5700"), 1);
  CHECK_THROWS_WITH_AS(gpu.end_query(), Contains("no query is active"), Error);
  gpu.begin_query();
  CHECK_THROWS_WITH_AS(gpu.begin_query(), Contains("already active"), Error);
  CHECK(gpu.end_query() == 0);
}

TEST_CASE("only lane widths 1, 4, 8 and 16 and known profiles exist") {
  CHECK_THROWS_WITH_AS(Gpu(profile("gf5700"), 1, 3), Contains("lane width must be 1, 4, 8 or 16"),
                       Error);
  CHECK_THROWS_WITH_AS(profile("voodoo2"),
                       Contains("known: gf5700, r300, gf6600, rtx4090, h200, h100"),
                       std::invalid_argument);
  CHECK(profile("gf5700").max_outputs == 1);
  CHECK(profile("gf5700").max_instructions == 1024);
  CHECK(profile("gf5700").branching == Branching::none);
  CHECK(profile("gf6600").max_outputs == 4);
  CHECK(profile("gf6600").branching == Branching::dynamic);
  CHECK(profile("r300").precision == Format::fp24);
  CHECK(profile("r300").computes(Format::fp32) == Format::fp24);  // R300 has only fp24 units
  CHECK(profile("r300").computes(Format::fp16) == Format::fp24);
  CHECK(profile("gf5700").computes(Format::fp16) == Format::fp16);
  CHECK(profile("gf5700").rate(Format::fp16) == 2 * profile("gf5700").rate(Format::fp32));
  CHECK(profiles().size() == 6);
  CHECK(profile("h200").max_outputs == 8);
}

TEST_CASE("a GL renderer string names the profile measured on that card, and no other") {
  // The strings NVIDIA's 580 driver gave on the two cards the GL device was measured on.
  const Profile* h200 = profile_for_renderer("NVIDIA H200/PCIe/SSE2");
  const Profile* h100 = profile_for_renderer("NVIDIA H100 80GB HBM3/PCIe/SSE2");
  REQUIRE(h200 != nullptr);
  REQUIRE(h100 != nullptr);
  CHECK(h200->name == "h200");
  CHECK(h100->name == "h100");
  // A card no profile was measured on, and the modeled cards of 2004, have none.
  CHECK(profile_for_renderer("llvmpipe (LLVM 15.0.6, 256 bits)") == nullptr);
  CHECK(profile_for_renderer("NVIDIA GeForce RTX 4090/PCIe/SSE2") == nullptr);
  // Nor do the cards whose names hold the words: a GH200, and an H100 of the PCIe kind (other
  // clocks and memory).
  CHECK(profile_for_renderer("NVIDIA GH200 480GB/PCIe/SSE2") == nullptr);
  CHECK(profile_for_renderer("NVIDIA H100 PCIe/PCIe/SSE2") == nullptr);
  CHECK(profile_for_renderer("") == nullptr);
  for (const Profile& p : profiles())
    CHECK((p.gl_renderer.empty() == (p.name != "h200" && p.name != "h100")));
}
