// PNG and JPEG decoding (depth images, overlay backgrounds) and PNG encoding of what was decoded.
#include <string>

#include "ellreloc/error.hpp"
#include "ellreloc/io/image_codec.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (io::DecodeAs as : {io::DecodeAs::Stored, io::DecodeAs::Bgr8}) {
    io::DecodedImage image;
    try {
      image = io::decodeImage(bytes, "fuzz", as, uint64_t{1} << 20);  // 1 Mpx: within the fuzzer's memory
    } catch (const Error&) {
      continue;
    }
    FUZZ_CHECK(image.width > 0 && image.height > 0);
    FUZZ_CHECK(as == io::DecodeAs::Stored || image.format == io::PixelFormat::Bgr8);
    const size_t stride = static_cast<size_t>(image.width) * io::bytesPerPixel(image.format);
    FUZZ_CHECK(image.pixels.size() == stride * image.height);
    // Whatever was decoded encodes, and decodes back to the same pixels.
    const std::string png = io::encodePng(image.pixels.data(), image.width, image.height, image.format, stride);
    const io::DecodedImage back = io::decodeImage(png, "again", io::DecodeAs::Stored, uint64_t{1} << 20);
    FUZZ_CHECK(back.format == image.format && back.pixels == image.pixels);
  }
  return 0;
}
