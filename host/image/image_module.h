// The C interface of the image module (libvgpu-image.so, host/image/image_module.cpp): the only
// code that links OpenImageIO. host/image/image_io.cpp dlopen()s it on the first image read or
// write, so a run that touches no image never loads OpenImageIO's ~250 shared libraries.
#pragma once

#include <cstddef>

extern "C" {

struct VgpuImageComparison {
  int width, height, channels;
  double failing_pixels, rms_error, psnr, max_error;
};

// Writes width x height pixels of `channels` floats (row 0 = top) to `path`, in the format its
// extension names (.png: 8-bit, clamped; .exr: float), without a timestamp. Returns 0, or -1
// with a one-line reason in err (at most err_size bytes, NUL-terminated).
int vgpu_image_write(const char* path, int width, int height, int channels, const float* pixels,
                     char* err, size_t err_size);

// Reads both images as float and compares every channel (ImageBufAlgo::compare) with
// `threshold` as the failure and warning level. Returns 0, or -1 with "PATH: reason" in err.
int vgpu_image_compare(const char* a, const char* b, double threshold, VgpuImageComparison* out,
                       char* err, size_t err_size);

// Decodes a PNG or JPEG image held in memory (n bytes): its size and channels, and its texels
// as floats (the stored values scaled to [0, 1], no colour conversion), row 0 = top, written
// into the width * height * channels floats alloc(ctx, count) returns. Returns 0, or -1 with a
// one-line reason in err.
int vgpu_image_read(const unsigned char* bytes, size_t n, float* (*alloc)(void* ctx, size_t count),
                    void* ctx, int* width, int* height, int* channels, char* err, size_t err_size);
}

// The names image_io.cpp looks up with dlsym.
#define VGPU_IMAGE_WRITE "vgpu_image_write"
#define VGPU_IMAGE_COMPARE "vgpu_image_compare"
#define VGPU_IMAGE_READ "vgpu_image_read"
