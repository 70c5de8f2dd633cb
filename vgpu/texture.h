// A texture: a 2D array of 1-4 channel texels in video memory, in one storage format.
// Programs read textures only through texture units (nearest sampling, integer texRECT
// coordinates, clamped at the edges) and write them only as render targets.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vgpu/format.h"

namespace vgpu {

class Texture {
 public:
  Texture() = default;
  // Allocates width x height texels of `channels` channels, all zero.
  Texture(std::string name, int width, int height, int channels, Format format = Format::fp32);
  // A copy is another texture in video memory (a new id); a move keeps the id.
  Texture(const Texture& o) : Texture(o, next_id()) {}
  Texture& operator=(const Texture& o) { return *this = Texture(o); }
  Texture(Texture&&) = default;
  Texture& operator=(Texture&&) = default;

  // Identity for devices that keep their own copy of a texture (the GL device's objects).
  uint64_t id() const { return id_; }

  const std::string& name() const { return name_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  Format format() const { return format_; }
  int bytes_per_texel() const { return channels_ * bytes_per_channel(format_); }
  uint64_t bytes() const { return uint64_t(width_) * height_ * bytes_per_texel(); }

  // Host access (uploads and read-backs): texel (x, y) channel c. Stores round to the format.
  float get(int x, int y, int c = 0) const { return data_[index(x, y) + c]; }
  void set(int x, int y, int c, float v) { data_[index(x, y) + c] = round_to(format_, v); }
  void fill(std::span<const float> texel);  // every texel = texel (channels() values)
  // Raw texel storage: channels() floats per texel, row-major, already rounded.
  std::span<const float> data() const { return data_; }
  const float* texel(int x, int y) const { return data_.data() + index(x, y); }
  float* texel_mut(int x, int y) { return data_.data() + index(x, y); }
  size_t index(int x, int y) const { return (size_t(y) * width_ + x) * channels_; }

 private:
  Texture(const Texture& o, uint64_t id)
      : name_(o.name_),
        width_(o.width_),
        height_(o.height_),
        channels_(o.channels_),
        format_(o.format_),
        data_(o.data_),
        id_(id) {}
  static uint64_t next_id();

  std::string name_;
  int width_ = 0, height_ = 0, channels_ = 0;
  Format format_ = Format::fp32;
  std::vector<float> data_;
  uint64_t id_ = next_id();
};

// An early-z / stencil style mask over a render target: one byte per pixel. A pass that tests
// it skips fragments whose value is 0 before shading (they are counted as masked, not shaded).
class Stencil {
 public:
  Stencil() = default;
  Stencil(int width, int height, uint8_t value = 1)
      : width_(width), height_(height), bits_(size_t(width) * height, value) {}
  int width() const { return width_; }
  int height() const { return height_; }
  uint8_t get(int x, int y) const { return bits_[size_t(y) * width_ + x]; }
  void set(int x, int y, uint8_t v) { bits_[size_t(y) * width_ + x] = v; }
  void fill(uint8_t v) { std::fill(bits_.begin(), bits_.end(), v); }
  const uint8_t* row(int y) const { return bits_.data() + size_t(y) * width_; }
  uint8_t* row_mut(int y) { return bits_.data() + size_t(y) * width_; }
  uint64_t count() const;  // pixels with a non-zero value

 private:
  int width_ = 0, height_ = 0;
  std::vector<uint8_t> bits_;
};

}  // namespace vgpu
