// Image files: writing renders and AOVs without ever leaving a partial file, and comparing two
// images (share of differing pixels, RMS error, PSNR). OpenImageIO is loaded on first use.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "host/scene/gltf_loader.h"

namespace host {

// Writes width x height pixels of `channels` floats (row 0 = top). The format follows the
// extension (.png: 8-bit, clamped to [0, 1]; .exr: float). The file is written under a
// temporary name and renamed at the end, so a failure leaves nothing behind. Throws
// host::InputError "PATH: problem".
void write_image(const std::string& path, int width, int height, int channels,
                 const std::vector<float>& pixels);

// Checks a path can be written as an image before any work is done (extension, directory).
void check_image_path(const std::string& path);
// The same for any output file whose extension (lower-cased, with the dot) must be one of
// `extensions`. Throws host::InputError "PATH: problem".
void check_output_path(const std::string& path, const std::vector<std::string>& extensions);
// Checks the directory a file is to be written in exists and is writable.
void check_output_dir(const std::string& path);

struct ImageComparison {
  int width = 0, height = 0, channels = 0;
  double differing_share = 0;  // pixels where some channel differs by more than `threshold`
  double rms_error = 0, psnr = 0, max_error = 0;
  double threshold = 0;
};
// Decodes a PNG or JPEG image held in memory (glTF textures: LoadOptions::read_image). Throws
// std::runtime_error with the reason (the loader names the file and the image).
ImagePixels decode_image(const std::vector<unsigned char>& bytes);

// `options` with read_image = decode_image: what a caller that renders textures loads with.
inline LoadOptions with_images(LoadOptions options = {}) {
  options.read_image = decode_image;
  return options;
}

// The anonymous resident bytes the image module's first use added to the process (OpenImageIO
// and the libraries it links, loaded and first called: their tables, relocated data and
// allocations, not a decoded image handed back; 0 before), for the memory model
// (host/report/memory_json.h).
uint64_t image_library_bytes();

// OpenImageIO's ImageBufAlgo::compare over every channel.
ImageComparison compare_images(const std::string& a, const std::string& b, double threshold);

}  // namespace host
