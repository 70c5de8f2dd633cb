// The GL device's operations: texture objects, compiled programs, framebuffers, queries.
#include "gl/gl_device.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <unordered_set>
#include <utility>

#include "gl/context.h"
#include "gl/gl.h"

namespace gl {

using vgpu::Error;
using vgpu::Format;
using vgpu::Texture;

struct GlDevice::GlTexture {
  GLuint name = 0;
  int width = 0, height = 0, channels = 0;
  GLenum format = 0;  // GL_RED..GL_RGBA
};

struct GlDevice::GlProgram {
  GLuint name = 0;
  GLint constants = -1;         // location of k[]
  std::vector<GLint> samplers;  // location of each sampler uniform, as GlslProgram::samplers
};

// A pass whose counters wait for the driver: its own discard count and its time.
struct GlDevice::Pending {
  size_t pass = SIZE_MAX;  // index in stats_.passes, if kept
  std::string program;
  uint64_t area = 0, write_per_fragment = 0;
  GLuint samples = 0, time = 0;
  int64_t passed = -1;  // samples that passed, once read
};

// The ids of the GL textures this device holds that no texture names any more. retired() runs
// on whichever thread dropped the id; the device frees them at its next call, with its context
// current. Only held ids are noted, so textures the device never met (an emulator's) cost one
// set lookup.
struct GlDevice::Retired final : vgpu::Texture::IdSink {
  std::mutex lock;
  std::unordered_set<uint64_t> held;
  std::vector<uint64_t> ids;
  std::atomic<bool> any{false};
  void retired(uint64_t id) override {
    std::lock_guard<std::mutex> locked(lock);
    if (held.erase(id)) {
      ids.push_back(id);
      any.store(true, std::memory_order_release);
    }
  }
  void hold(uint64_t id) {
    std::lock_guard<std::mutex> locked(lock);
    held.insert(id);
  }
  std::vector<uint64_t> take() {
    std::lock_guard<std::mutex> locked(lock);
    any.store(false, std::memory_order_relaxed);
    return std::exchange(ids, {});
  }
};

namespace {

// Texture work outside a pass (creation, upload, download) binds on this unit, above the
// program's 16, so it never disturbs a pass's bindings.
constexpr GLenum kScratchUnit = GL_TEXTURE0 + vgpu::kMaxTextureUnits;

GLenum pixel_format(int channels) {
  static const GLenum f[] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
  return f[channels - 1];
}

GLenum internal_format(const Texture& t) {
  static const GLenum f32[] = {GL_R32F, GL_RG32F, GL_RGB32F, GL_RGBA32F};
  static const GLenum f16[] = {GL_R16F, GL_RG16F, GL_RGB16F, GL_RGBA16F};
  switch (t.format()) {
    case Format::fp32:
      return f32[t.channels() - 1];
    case Format::fp16:
      return f16[t.channels() - 1];
    default:
      throw Error("texture '" + t.name() +
                  "' is fp24: OpenGL has no 24-bit float texture format (the GL device runs fp32)");
  }
}

GLuint compile(GLenum kind, const std::string& source, const std::string& what) {
  const GLuint s = glCreateShader(kind);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    std::string first(log);
    if (auto nl = first.find('\n'); nl != std::string::npos) first.resize(nl);
    throw Error("the GL driver rejected " + what + ": " + first);
  }
  return s;
}

}  // namespace

GlDevice::GlDevice(const vgpu::Profile& profile, const std::string& device, ReadbackWait wait)
    : profile_(profile),
      wait_(wait),
      ctx_(std::make_unique<Context>(device)),
      retired_(std::make_unique<Retired>()) {
  vgpu::Texture::subscribe(retired_.get());
  if (wait_ == ReadbackWait::automatic)
    wait_ = ctx_->software() ? ReadbackWait::block : ReadbackWait::poll;
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenFramebuffers(1, &clear_fbo_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
  stats_.device_timed = true;
}

GlDevice::~GlDevice() {
  vgpu::Texture::unsubscribe(retired_.get());
  ctx_->make_current();
  for (auto& [id, t] : textures_) glDeleteTextures(1, &t->name);
  for (auto& [src, p] : compiled_) glDeleteProgram(p->name);
  for (auto& [key, fbo] : fbos_) glDeleteFramebuffers(1, &fbo);
  for (const Pending& p : pending_) {
    glDeleteQueries(1, &p.samples);
    glDeleteQueries(1, &p.time);
  }
  for (const auto* pool : {&free_samples_, &free_times_})
    if (!pool->empty()) glDeleteQueries(GLsizei(pool->size()), pool->data());
  glDeleteFramebuffers(1, &clear_fbo_);
  glDeleteVertexArrays(1, &vao_);
}

std::string GlDevice::description() const {
  return ctx_->renderer() + ", OpenGL " + ctx_->version() + ", " + ctx_->platform();
}

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

GlDevice::GlTexture& GlDevice::texture(const Texture& t) {
  if (auto it = textures_.find(t.id()); it != textures_.end()) return *it->second;
  // Everything that can refuse the texture comes before the GL name and the map's entry, so a
  // refused texture leaves neither behind.
  check_texture(t);
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (t.width() > max_size || t.height() > max_size)
    throw Error("texture '" + t.name() + "' is " + std::to_string(t.width()) + "x" +
                std::to_string(t.height()) + " texels; this GL driver allows " +
                std::to_string(max_size));
  const GLenum internal = internal_format(t);
  auto g = std::make_unique<GlTexture>();
  g->width = t.width();
  g->height = t.height();
  g->channels = t.channels();
  g->format = pixel_format(t.channels());
  glGenTextures(1, &g->name);
  glActiveTexture(kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, g->name);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  // A new texture holds what the host holds (zeros for a dynamic one, as on the emulator).
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), t.width(), t.height(), 0, g->format, GL_FLOAT,
               t.data().data());
  GlTexture& made = *(textures_[t.id()] = std::move(g));
  retired_->hold(t.id());
  ++times_.textures_made;
  return made;
}

void GlDevice::free_retired() {
  if (!retired_->any.load(std::memory_order_acquire)) return;
  const std::vector<uint64_t> ids = retired_->take();
  for (uint64_t id : ids)
    if (auto it = textures_.find(id); it != textures_.end()) {
      glDeleteTextures(1, &it->second->name);
      textures_.erase(it);
      ++times_.textures_freed;
    }
  // A framebuffer is kept per list of target ids: one holding any retired id goes.
  std::erase_if(fbos_, [&](const auto& entry) {
    const bool gone = std::find_first_of(entry.first.begin(), entry.first.end(), ids.begin(),
                                         ids.end()) != entry.first.end();
    if (gone) {
      glDeleteFramebuffers(1, &entry.second);
      ++times_.framebuffers_freed;
    }
    return gone;
  });
}

void GlDevice::upload(const Texture& t) {
  ctx_->make_current();
  const auto t0 = std::chrono::steady_clock::now();
  free_retired();  // its GL deletions are this call's host time
  const bool fresh = !textures_.count(t.id());
  GlTexture& g = texture(t);
  if (!fresh) {  // else created from the host's texels just now
    glActiveTexture(kScratchUnit);
    glBindTexture(GL_TEXTURE_2D, g.name);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, t.width(), t.height(), g.format, GL_FLOAT,
                    t.data().data());
  }
  times_.upload_ms += ms_since(t0);
}

void GlDevice::download(Texture& t) {
  ctx_->make_current();
  const auto t0 = std::chrono::steady_clock::now();
  free_retired();  // its GL deletions are this call's host time
  GlTexture& g = texture(t);
  glActiveTexture(kScratchUnit);
  glBindTexture(GL_TEXTURE_2D, g.name);
  glGetTexImage(GL_TEXTURE_2D, 0, g.format, GL_FLOAT, t.texel_mut(0, 0));
  vgpu::count_download(stats_, t);
  times_.download_ms += ms_since(t0);
}

void GlDevice::use_program(const vgpu::Program& program) {
  program_ = &program;
  if (program.id() == loaded_program_) return;
  loaded_program_ = program.id();
  vgpu::count_program_load(stats_, program, profile_);
}

void GlDevice::bind_texture(int unit, const Texture& texture) {
  if (unit < 0 || unit >= vgpu::kMaxTextureUnits)
    throw Error("texture unit " + std::to_string(unit) + " does not exist (0.." +
                std::to_string(vgpu::kMaxTextureUnits - 1) + ")");
  check_texture(texture);
  units_[size_t(unit)] = &texture;
}

void GlDevice::unbind_textures() {
  units_.fill(nullptr);
}

void GlDevice::set_targets(std::initializer_list<Texture*> targets) {
  targets_.assign(targets.begin(), targets.end());
  for (Texture* t : targets_) check_texture(*t);
}

void GlDevice::set_stencil_test(const vgpu::Stencil* stencil) {
  if (stencil) throw Error("the GL device has no stencil masks (use the vgpu for --masks on)");
}

void GlDevice::set_stencil_write(vgpu::Stencil* stencil) {
  if (stencil) throw Error("the GL device has no stencil masks (use the vgpu for --masks on)");
}

void GlDevice::set_work_mask(const vgpu::Stencil*) {
  // The work mask only spares the emulator host work whose result is provably unchanged; a GL
  // driver runs every fragment, which gives the same result.
}

void GlDevice::clear(Texture& t, std::initializer_list<float> value) {
  ctx_->make_current();
  const auto t0 = std::chrono::steady_clock::now();
  free_retired();  // its GL deletions are this call's host time
  if (int(value.size()) != t.channels())
    throw Error("clear of texture '" + t.name() + "': " + std::to_string(value.size()) +
                " values for " + std::to_string(t.channels()) + " channels");
  GlTexture& g = texture(t);
  float v[4] = {0, 0, 0, 1};
  std::copy(value.begin(), value.end(), v);
  glBindFramebuffer(GL_FRAMEBUFFER, clear_fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g.name, 0);
  const GLenum buf = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &buf);
  glClearBufferfv(GL_COLOR, 0, v);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
  vgpu::Counters c;
  c.clears = 1;
  c.bytes_written = t.bytes();
  stats_.totals += c;
  times_.clear_ms += ms_since(t0);
}

GlDevice::GlProgram& GlDevice::program_for(const vgpu::Program& p) {
  Recorded& r = recorded_[p.id()];
  const std::span<const std::byte> bytes = p.uniform_bytes();
  auto same = [&](const Variant& v) {
    return std::equal(v.uniforms.begin(), v.uniforms.end(), bytes.begin(), bytes.end());
  };
  if (r.current && same(*r.current)) return *r.current->gl;
  const auto seen = std::find_if(r.variants.begin(), r.variants.end(),
                                 [&](const std::unique_ptr<Variant>& v) { return same(*v); });
  if (seen != r.variants.end()) {
    r.current = seen->get();
    ++times_.variants_reused;
    return *r.current->gl;
  }
  auto v = std::make_unique<Variant>();
  v->uniforms.assign(bytes.begin(), bytes.end());
  v->glsl = vgpu::to_glsl(p);
  auto found = compiled_.find(v->glsl.source);
  if (found == compiled_.end()) {  // compiled and linked before it is kept: a failure keeps none
    const std::string what = std::string("program '") + p.name() + "'";
    const GLuint vs = compile(GL_VERTEX_SHADER, vgpu::fullscreen_vertex_shader(), what);
    GLuint fs = 0;
    try {
      fs = compile(GL_FRAGMENT_SHADER, v->glsl.source, what);
    } catch (...) {
      glDeleteShader(vs);
      throw;
    }
    auto g = std::make_unique<GlProgram>();
    g->name = glCreateProgram();
    glAttachShader(g->name, vs);
    glAttachShader(g->name, fs);
    if (!dump_dir_.empty())
      glProgramParameteri(g->name, GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
    glLinkProgram(g->name);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(g->name, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[1024] = {};
      glGetProgramInfoLog(g->name, sizeof log, nullptr, log);
      glDeleteProgram(g->name);
      throw Error("the GL driver could not link " + what + ": " + log);
    }
    if (!dump_dir_.empty()) dump(g->name, p.name(), v->glsl.source);
    g->constants = glGetUniformLocation(g->name, "k");
    ++times_.programs_linked;
    for (const std::string& s : v->glsl.samplers)
      g->samplers.push_back(glGetUniformLocation(g->name, s.c_str()));
    found = compiled_.emplace(v->glsl.source, std::move(g)).first;
  }
  ++times_.variants_printed;
  v->gl = found->second.get();
  // draw() needs the constants and units alone; the text is compiled_'s key already.
  v->glsl.source = std::string();
  r.current = v.get();
  r.variants.push_back(std::move(v));
  if (r.variants.size() > kRecordedVariants) r.variants.erase(r.variants.begin());
  return *r.current->gl;
}

GlDevice::Linked GlDevice::link(const vgpu::Program& p) {
  ctx_->make_current();
  const GlProgram& g = program_for(p);
  Linked l;
  l.samplers.assign(g.samplers.begin(), g.samplers.end());
  for (int o = 0; o < p.outputs(); ++o)
    l.outputs.push_back(glGetFragDataLocation(g.name, ("out" + std::to_string(o)).c_str()));
  return l;
}

void GlDevice::dump(unsigned program, const std::string& name, const std::string& source) {
  std::string file = name;
  for (char& c : file)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  char prefix[8];
  std::snprintf(prefix, sizeof prefix, "%02d_", dumped_++);
  const std::string base = dump_dir_ + "/" + prefix + file;
  std::ofstream(base + ".glsl") << source;
  GLint length = 0;
  glGetProgramiv(program, GL_PROGRAM_BINARY_LENGTH, &length);
  std::vector<char> binary(size_t(std::max(length, 0)));
  GLenum format = 0;
  GLsizei written = 0;
  if (length > 0) glGetProgramBinary(program, length, &written, &format, binary.data());
  std::ofstream(base + ".bin", std::ios::binary).write(binary.data(), written);
}

unsigned GlDevice::framebuffer_for(const std::vector<Texture*>& targets) {
  std::vector<uint64_t> key;
  for (const Texture* t : targets) key.push_back(t->id());
  auto [it, fresh] = fbos_.try_emplace(key, 0u);
  if (fresh) {
    glGenFramebuffers(1, &it->second);
    glBindFramebuffer(GL_FRAMEBUFFER, it->second);
    std::vector<GLenum> bufs;
    for (size_t i = 0; i < targets.size(); ++i) {
      glFramebufferTexture2D(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_TEXTURE_2D,
                             texture(*targets[i]).name, 0);
      bufs.push_back(GLenum(GL_COLOR_ATTACHMENT0 + i));
    }
    glDrawBuffers(GLsizei(bufs.size()), bufs.data());
    ++times_.framebuffers_made;
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("render target '" + targets[0]->name() + "' (" +
                  std::to_string(targets[0]->channels()) +
                  " channels) is not renderable on this GL driver");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, it->second);
  return it->second;
}

const vgpu::PassRecord& GlDevice::draw() {
  if (targets_.empty())
    throw Error(program_ ? "program '" + std::string(program_->name()) +
                               "': draw with no render target set"
                         : std::string("draw: no render target set"));
  return draw(vgpu::Rect{0, 0, targets_[0]->width(), targets_[0]->height()});
}

const vgpu::PassRecord& GlDevice::draw(const vgpu::Rect& rect) {
  ctx_->make_current();
  const auto t0 = std::chrono::steady_clock::now();
  free_retired();  // its GL deletions are this call's host time
  if (!program_) throw Error("draw: no program bound");
  const vgpu::Program& p = *program_;
  const vgpu::Program::Analysis a = p.analyze();
  vgpu::check_pass(profile_, p, a, units_.data(), targets_, rect);

  GlProgram& prog = program_for(p);
  const vgpu::GlslProgram& glsl = recorded_[p.id()].current->glsl;
  // Targets first: creating a texture binds it to the active unit.
  framebuffer_for(targets_);
  glUseProgram(prog.name);
  if (prog.constants >= 0)
    glUniform1fv(prog.constants, GLsizei(glsl.constants.size()), glsl.constants.data());
  for (size_t i = 0; i < glsl.units.size(); ++i) {
    const int unit = glsl.units[i];
    const GLuint name = texture(*units_[size_t(unit)]).name;
    glActiveTexture(GLenum(GL_TEXTURE0 + unit));
    glBindTexture(GL_TEXTURE_2D, name);
    glUniform1i(prog.samplers[i], unit);
  }
  glViewport(rect.x0, rect.y0, rect.width(), rect.height());

  Pending pend;
  // A query object keeps the target it was first used with: one pool per target.
  auto query = [&](std::vector<unsigned>& pool) {
    if (pool.empty()) {
      pool.resize(64);
      glGenQueries(64, pool.data());
    }
    const GLuint q = pool.back();
    pool.pop_back();
    return q;
  };
  pend.samples = query(free_samples_);
  pend.time = query(free_times_);
  glBeginQuery(GL_SAMPLES_PASSED, pend.samples);
  glBeginQuery(GL_TIME_ELAPSED, pend.time);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEndQuery(GL_TIME_ELAPSED);
  glEndQuery(GL_SAMPLES_PASSED);

  // Counted as if nothing were discarded until the driver says how many were (settle()).
  vgpu::Counters c = vgpu::pass_counters(a, units_.data(), targets_, rect.area(), rect.area(), 0);
  c.host_ms = ms_since(t0);
  times_.draw_ms += c.host_ms;
  pend.area = rect.area();
  for (const Texture* t : targets_) pend.write_per_fragment += uint64_t(t->bytes_per_texel());
  pend.program = p.name();
  vgpu::FrameStats::ProgramTotals& totals =
      stats_.program(p.name(), p.paper_name(), a.instructions);
  totals.counters += c;
  totals.instructions = a.instructions;
  stats_.totals += c;
  vgpu::PassRecord rec{p.name(), rect.width(), rect.height(), c, -1};
  const vgpu::PassRecord* out = &last_pass_;
  if (stats_.keep_pass_records) {
    pend.pass = stats_.passes.size();
    stats_.passes.push_back(std::move(rec));
    out = &stats_.passes.back();
  } else {
    last_pass_ = std::move(rec);
  }
  pending_.push_back(std::move(pend));
  // Keep the number of queries in flight bounded on long frames (the oldest are long done).
  if (pending_.size() >= 8192 && !query_active_) settle(1024);
  return *out;
}

void GlDevice::begin_query() {
  if (query_active_) throw Error("begin_query: a query is already active");
  query_active_ = true;
  query_first_ = pending_.size();
}

uint64_t GlDevice::end_query() {
  ctx_->make_current();
  if (!query_active_) throw Error("end_query: no query is active");
  query_active_ = false;
  // The read-back: wait for the passes drawn inside the query and sum what survived them.
  const auto t0 = std::chrono::steady_clock::now();
  if (wait_ == ReadbackWait::poll && query_first_ < pending_.size()) {
    glFlush();
    for (size_t i = query_first_; i < pending_.size(); ++i) {
      GLuint ready = 0;
      while (!ready) glGetQueryObjectuiv(pending_[i].samples, GL_QUERY_RESULT_AVAILABLE, &ready);
    }
  }
  uint64_t n = 0;
  for (size_t i = query_first_; i < pending_.size(); ++i) {
    GLuint64 v = 0;
    glGetQueryObjectui64v(pending_[i].samples, GL_QUERY_RESULT, &v);
    pending_[i].passed = int64_t(v);
    n += v;
  }
  times_.wait_ms += ms_since(t0);
  vgpu::count_readback(stats_, program_, n);
  return n;
}

void GlDevice::settle(size_t keep) {
  ctx_->make_current();
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = pending_.size() > keep ? pending_.size() - keep : 0;
  for (size_t i = 0; i < n; ++i) {
    Pending& p = pending_[i];
    GLuint64 passed = 0, ns = 0;
    if (p.passed >= 0)
      passed = GLuint64(p.passed);
    else
      glGetQueryObjectui64v(p.samples, GL_QUERY_RESULT, &passed);
    glGetQueryObjectui64v(p.time, GL_QUERY_RESULT, &ns);
    free_samples_.push_back(p.samples);
    free_times_.push_back(p.time);
    vgpu::Counters d;  // what the provisional counters lacked
    const uint64_t discarded = p.area - std::min<uint64_t>(p.area, passed);
    d.fragments_discarded = discarded;
    d.device_ms = double(ns) * 1e-6;
    const uint64_t less_written = discarded * p.write_per_fragment;
    auto apply = [&](vgpu::Counters& c) {
      c.fragments_discarded += d.fragments_discarded;
      c.bytes_written -= less_written;
      c.device_ms += d.device_ms;
    };
    apply(stats_.totals);
    for (auto& t : stats_.programs)
      if (t.name == p.program) apply(t.counters);
    if (p.pass != SIZE_MAX && p.pass < stats_.passes.size()) apply(stats_.passes[p.pass].counters);
  }
  pending_.erase(pending_.begin(), pending_.begin() + std::ptrdiff_t(n));
  if (query_active_) query_first_ -= std::min(query_first_, n);
  times_.settle_ms += ms_since(t0);
}

void GlDevice::finish() {
  ctx_->make_current();
  const auto t0 = std::chrono::steady_clock::now();
  glFinish();
  times_.settle_ms += ms_since(t0);
  settle(0);
}

vgpu::FrameStats& GlDevice::stats() {
  if (!query_active_ && !pending_.empty()) settle(0);
  return stats_;
}

}  // namespace gl
