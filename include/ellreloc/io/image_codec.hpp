#pragma once
/// \file image_codec.hpp
/// PNG and JPEG bytes to pixels and back, through libpng and libjpeg. The library decodes depth
/// PNGs and overlay backgrounds and encodes depth images, overlays and figures with these instead
/// of OpenCV's imgcodecs, whose Debian build loads GDAL, GDCM and a hundred more libraries at
/// start-up (about 70 ms for every process that links it, docs/benchmarks.md).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ellreloc::io {

/// Pixel layouts: 8-bit grey, 8-bit colour in blue, green, red order (as OpenCV keeps it) and
/// 16-bit grey (samples in the machine's byte order).
enum class PixelFormat { Grey8, Bgr8, Grey16 };

/// Bytes per pixel of a layout.
int bytesPerPixel(PixelFormat format);

/// A decoded image: rows top to bottom, packed (width x bytesPerPixel bytes each).
struct DecodedImage {
  int width = 0;
  int height = 0;
  PixelFormat format = PixelFormat::Grey8;
  std::vector<uint8_t> pixels;
};

/// How to decode: keep grey or colour and 8 or 16 bits as stored (alpha dropped, palettes and
/// bit depths below 8 expanded), or turn every image into 8-bit colour.
enum class DecodeAs { Stored, Bgr8 };

/// Decodes PNG or JPEG bytes (told apart by their signature). Images declaring more than
/// `max_pixels` pixels in their header (64 Mpx by default: a few hundred bytes of PNG can
/// declare gigabytes) are refused before any pixel is decoded. Throws
/// ellreloc::Error("NAME: ...") for bytes that are neither, are corrupt or are too large.
DecodedImage decodeImage(const std::string& bytes, const std::string& name, DecodeAs as,
                         uint64_t max_pixels = uint64_t{1} << 26);

/// PNG bytes of an image whose rows start `row_bytes` apart; compression 0 (none) to 9, by
/// default 1: the fastest, with one row filter and run-length matching only, for depth images
/// and rendered frames. Throws ellreloc::Error for a size or row length it cannot encode.
std::string encodePng(const void* pixels, int width, int height, PixelFormat format, size_t row_bytes,
                      int compression = 1);

}  // namespace ellreloc::io
