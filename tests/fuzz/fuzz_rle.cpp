// COCO RLE decoding and everything that walks the runs: moments, the regular-mask test, fits.
#include <string>

#include "ellreloc/core/mask.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/observe/regular_mask.hpp"
#include "ellreloc/core/rle.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  if (size < 2) return 0;
  // First two bytes: the mask's size (up to 64 x 64); the rest: the compressed counts string.
  RleMask rle;
  rle.height = 1 + data[0] % 64;
  rle.width = 1 + data[1] % 64;
  const auto counts = decodeRleString(std::string(reinterpret_cast<const char*>(data + 2), size - 2));
  if (!counts) return 0;
  rle.counts = *counts;
  FUZZ_CHECK(decodeRleString(encodeRleString(rle.counts)) == counts);  // the codec round trip
  const auto mask = decodeMask(rle);
  FUZZ_CHECK(mask.has_value() == rle.isConsistent());
  if (!mask) return 0;
  FUZZ_CHECK(encodeMask(*mask).totalPixels() == rle.totalPixels());
  (void)rleMoments(rle);
  // A crop, grown by any margin, encodes as the whole mask (the canonical runs of its pixels).
  if (const auto crop = decodeMaskCrop(rle, data[0] % 70))
    FUZZ_CHECK(encodeMask(*crop).counts == encodeMask(*mask).counts);
  const RegularVerdict v = testRegularMask(rle);
  for (MaskFitMethod m :
       {MaskFitMethod::Moments, MaskFitMethod::Direct, MaskFitMethod::Quadrilateral, MaskFitMethod::Hull}) {
    const auto e = fitMaskEllipse(rle, m, &v);
    FUZZ_CHECK(!e || e->isValid());  // never NaN
  }
  Detection d;
  d.bbox = Box(0, 0, rle.width, rle.height);
  d.mask = rle;
  for (ObservationPolicy p : {ObservationPolicy::Paper, ObservationPolicy::Solid, ObservationPolicy::Mask}) {
    ObserveOptions o;
    o.policy = p;
    const ObserveResult r = observeDetection(d, rle.width, rle.height, o);
    FUZZ_CHECK(!r.observation || r.observation->ellipse.isValid());
  }
  return 0;
}
