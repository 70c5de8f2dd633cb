// Texture storage and the stencil mask.
#include "vgpu/texture.h"

#include <algorithm>
#include <atomic>
#include <stdexcept>

namespace vgpu {

Texture::Texture(std::string name, int width, int height, int channels, Format format)
    : name_(std::move(name)), width_(width), height_(height), channels_(channels), format_(format) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("texture " + name_ + ": empty size");
  if (channels < 1 || channels > 4)
    throw std::invalid_argument("texture " + name_ + ": texels have 1 to 4 channels");
  data_.assign(size_t(width) * height * channels, 0.0f);
}

uint64_t Texture::next_id() {
  static std::atomic<uint64_t> next{1};
  return next++;
}

void Texture::fill(std::span<const float> texel) {
  for (size_t i = 0; i < data_.size(); ++i) data_[i] = round_to(format_, texel[i % channels_]);
}

uint64_t Stencil::count() const {
  return uint64_t(std::count_if(bits_.begin(), bits_.end(), [](uint8_t b) { return b != 0; }));
}

}  // namespace vgpu
