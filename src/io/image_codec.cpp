#include "ellreloc/io/image_codec.hpp"

// libpng and libjpeg report errors by longjmp. Each setjmp below sits in a function whose own
// locals need no destruction, and the jump comes back to it from C code only, so no C++
// destructor is skipped; every object that outlives the jump belongs to the caller.
#include <jpeglib.h>
#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>

#include "ellreloc/error.hpp"

namespace ellreloc::io {

int bytesPerPixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::Grey8:
      return 1;
    case PixelFormat::Bgr8:
      return 3;
    case PixelFormat::Grey16:
      return 2;
  }
  return 1;
}

namespace {

bool littleEndian() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

std::string tooLarge(uint64_t width, uint64_t height, uint64_t max_pixels) {
  return "declares a " + std::to_string(width) + "x" + std::to_string(height) + " image; images are limited to " +
         std::to_string(max_pixels) + " pixels";
}

// --- PNG -----------------------------------------------------------------------------------------

/// What libpng's callbacks share: the bytes being read or the string being written, and the
/// message of the error that ended a call.
struct PngIo {
  const std::string* in = nullptr;
  size_t offset = 0;
  std::string* out = nullptr;
  char message[256] = "";
};

void pngError(png_structp png, png_const_charp message) {
  auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
  std::snprintf(io->message, sizeof io->message, "%s", message);
  png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}

void pngRead(png_structp png, png_bytep data, size_t length) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  if (io->in->size() - io->offset < length) png_error(png, "truncated PNG data");
  std::memcpy(data, io->in->data() + io->offset, length);
  io->offset += length;
}

void pngWrite(png_structp png, png_bytep data, size_t length) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  bool appended = true;
  try {
    io->out->append(reinterpret_cast<const char*>(data), length);
  } catch (...) {
    appended = false;  // no longjmp out of a handler: it would skip the end of the catch
  }
  if (!appended) png_error(png, "out of memory");
}

void pngFlush(png_structp) {}

/// Reads the image into `out`; false (with io.message set) on any error.
bool readPng(png_structp png, png_infop info, PngIo& io, DecodeAs as, DecodedImage& out, std::vector<png_bytep>& rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, &io, pngRead);
  png_read_info(png, info);  // the size was checked from these very IHDR bytes (refuseTooLargePng)
  const uint64_t width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  const int colour = png_get_color_type(png, info);
  const int bits = png_get_bit_depth(png, info);
  const bool grey = (colour & PNG_COLOR_MASK_COLOR) == 0;
  png_set_palette_to_rgb(png);          // palettes become colour,
  png_set_expand_gray_1_2_4_to_8(png);  // grey of 1, 2 or 4 bits 8-bit grey,
  png_set_strip_alpha(png);             // alpha channels are dropped
  if (as == DecodeAs::Bgr8 && grey) png_set_gray_to_rgb(png);
  const bool keep16 = as == DecodeAs::Stored && grey && bits == 16;
  if (keep16 && littleEndian()) png_set_swap(png);
  if (!keep16) png_set_strip_16(png);
  if (!grey || as == DecodeAs::Bgr8) png_set_bgr(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  out.width = static_cast<int>(width);
  out.height = static_cast<int>(height);
  out.format = keep16 ? PixelFormat::Grey16 : (grey && as == DecodeAs::Stored ? PixelFormat::Grey8 : PixelFormat::Bgr8);
  const size_t stride = width * bytesPerPixel(out.format);
  if (png_get_rowbytes(png, info) != stride) png_error(png, "unexpected row layout after conversion");
  out.pixels.resize(stride * height);
  rows.resize(height);
  for (size_t y = 0; y < height; ++y) rows[y] = out.pixels.data() + y * stride;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  return true;
}

struct PngReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngReader() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
};

/// The size the PNG header (IHDR, which must come first) declares, read before libpng checks its
/// CRC, so that an image too large is refused as such even when the rest is damaged.
void refuseTooLargePng(const std::string& bytes, const std::string& name, uint64_t max_pixels) {
  if (bytes.size() < 24 || bytes.compare(12, 4, "IHDR") != 0) return;  // libpng says what is wrong
  const auto be32 = [&](size_t at) {
    uint64_t v = 0;
    for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  const uint64_t width = be32(16), height = be32(20);
  if (width * height > max_pixels) throw Error(name + ": " + tooLarge(width, height, max_pixels));
}

DecodedImage decodePng(const std::string& bytes, const std::string& name, DecodeAs as, uint64_t max_pixels) {
  refuseTooLargePng(bytes, name, max_pixels);
  PngIo io;
  io.in = &bytes;
  PngReader reader;
  reader.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &io, pngError, pngWarning);
  if (reader.png) reader.info = png_create_info_struct(reader.png);
  if (!reader.png || !reader.info) throw Error(name + ": out of memory decoding a PNG image");
  DecodedImage out;
  std::vector<png_bytep> rows;
  if (!readPng(reader.png, reader.info, io, as, out, rows))
    throw Error(name + ": cannot decode PNG image (" + io.message + ")");
  return out;
}

// --- JPEG ----------------------------------------------------------------------------------------

struct JpegErrors {
  jpeg_error_mgr manager;  // first, so that libjpeg's pointer to it is a pointer to the whole
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = "";
};

void jpegExit(j_common_ptr codec) {
  auto* errors = reinterpret_cast<JpegErrors*>(codec->err);
  (*codec->err->format_message)(codec, errors->message);
  std::longjmp(errors->jump, 1);
}

void jpegMessage(j_common_ptr) {}  // warnings (e.g. a truncated file, whose rest is grey) stay quiet

bool readJpeg(jpeg_decompress_struct& codec, JpegErrors& errors, const std::string& bytes, DecodeAs as,
              uint64_t max_pixels, DecodedImage& out) {
  if (setjmp(errors.jump)) return false;
  jpeg_mem_src(&codec, reinterpret_cast<const unsigned char*>(bytes.data()), static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&codec, TRUE);
  if (uint64_t{codec.image_width} * codec.image_height > max_pixels) {
    std::snprintf(errors.message, sizeof errors.message, "%s",
                  tooLarge(codec.image_width, codec.image_height, max_pixels).c_str());
    return false;
  }
  const bool grey = as == DecodeAs::Stored && codec.jpeg_color_space == JCS_GRAYSCALE;
  codec.out_color_space = grey ? JCS_GRAYSCALE : JCS_EXT_BGR;
  jpeg_start_decompress(&codec);
  out.width = static_cast<int>(codec.output_width);
  out.height = static_cast<int>(codec.output_height);
  out.format = grey ? PixelFormat::Grey8 : PixelFormat::Bgr8;
  const size_t stride = size_t{codec.output_width} * bytesPerPixel(out.format);
  if (size_t{codec.output_width} * codec.output_components != stride) {
    std::snprintf(errors.message, sizeof errors.message, "unexpected number of colour components");
    return false;
  }
  out.pixels.resize(stride * codec.output_height);
  while (codec.output_scanline < codec.output_height) {
    JSAMPROW row = out.pixels.data() + size_t{codec.output_scanline} * stride;
    jpeg_read_scanlines(&codec, &row, 1);
  }
  jpeg_finish_decompress(&codec);
  return true;
}

struct JpegReader {
  jpeg_decompress_struct codec{};
  JpegErrors errors;
  bool created = false;
  ~JpegReader() {
    if (created) jpeg_destroy_decompress(&codec);
  }
};

/// Creates the decompressor; false when libjpeg cannot (out of memory).
bool createJpeg(JpegReader& reader) {
  if (setjmp(reader.errors.jump)) return false;
  jpeg_create_decompress(&reader.codec);
  reader.created = true;
  return true;
}

DecodedImage decodeJpeg(const std::string& bytes, const std::string& name, DecodeAs as, uint64_t max_pixels) {
  JpegReader reader;
  reader.codec.err = jpeg_std_error(&reader.errors.manager);
  reader.errors.manager.error_exit = jpegExit;
  reader.errors.manager.output_message = jpegMessage;
  if (!createJpeg(reader)) throw Error(name + ": cannot decode JPEG image (" + reader.errors.message + ")");
  DecodedImage out;
  if (!readJpeg(reader.codec, reader.errors, bytes, as, max_pixels, out))
    throw Error(name + ": cannot decode JPEG image (" + reader.errors.message + ")");
  return out;
}

// --- PNG encoding --------------------------------------------------------------------------------

bool writePng(png_structp png, png_infop info, PngIo& io, const uint8_t* pixels, int width, int height,
              PixelFormat format, size_t row_bytes, int compression) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, &io, pngWrite, pngFlush);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height),
               format == PixelFormat::Grey16 ? 16 : 8,
               format == PixelFormat::Bgr8 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, compression);
  if (compression <= 1) {  // speed first: one cheap row filter and run-length matching only
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_strategy(png, Z_RLE);
  }
  png_write_info(png, info);
  if (format == PixelFormat::Bgr8) png_set_bgr(png);
  if (format == PixelFormat::Grey16 && littleEndian()) png_set_swap(png);
  for (int y = 0; y < height; ++y) png_write_row(png, pixels + static_cast<size_t>(y) * row_bytes);
  png_write_end(png, nullptr);
  return true;
}

struct PngWriter {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWriter() { png_destroy_write_struct(&png, info ? &info : nullptr); }
};

}  // namespace

DecodedImage decodeImage(const std::string& bytes, const std::string& name, DecodeAs as, uint64_t max_pixels) {
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static const unsigned char kJpeg[3] = {0xff, 0xd8, 0xff};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPng, 8) == 0) return decodePng(bytes, name, as, max_pixels);
  if (bytes.size() >= 3 && std::memcmp(bytes.data(), kJpeg, 3) == 0) return decodeJpeg(bytes, name, as, max_pixels);
  throw Error(name + ": not a PNG or JPEG image");
}

std::string encodePng(const void* pixels, int width, int height, PixelFormat format, size_t row_bytes,
                      int compression) {
  if (width <= 0 || height <= 0 || width > 1000000 || height > 1000000)
    throw Error("cannot encode a " + std::to_string(width) + "x" + std::to_string(height) + " image as PNG");
  if (pixels == nullptr || row_bytes < static_cast<size_t>(width) * bytesPerPixel(format))
    throw Error("cannot encode a PNG image whose rows are shorter than its width");
  if (compression < 0 || compression > 9) throw Error("PNG compression must be 0 to 9");
  std::string out;
  PngIo io;
  io.out = &out;
  PngWriter writer;
  writer.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &io, pngError, pngWarning);
  if (writer.png) writer.info = png_create_info_struct(writer.png);
  if (!writer.png || !writer.info) throw Error("out of memory encoding a PNG image");
  if (!writePng(writer.png, writer.info, io, static_cast<const uint8_t*>(pixels), width, height, format, row_bytes,
                compression))
    throw Error(std::string("PNG encoding failed (") + io.message + ")");
  return out;
}

}  // namespace ellreloc::io
