// The map and detections JSON readers and the OA-SLAM text map reader: any bytes give a map,
// detections or ellreloc::Error, never a crash or another exception.
#include <string>

#include "ellreloc/error.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ObjectMap m = io::parseMapJson(text, "fuzz.json");
    // The reader promises valid ellipsoids that relocalization can use, and a unit that is a length.
    FUZZ_CHECK(validUnitMetres(m.unit_metres));
    for (const MapObject& o : m.objects) FUZZ_CHECK(o.ellipsoid.isValid() && mapObjectUsable(o, m.unit_metres));
  } catch (const Error&) {
  }
  try {
    (void)io::parseOaSlamMap(text, "fuzz.txt");
  } catch (const Error&) {
  }
  try {
    for (const DetectionFrame& f : io::parseDetectionsJson(text, "fuzz.json"))
      for (const Detection& d : f.detections) FUZZ_CHECK(!d.mask || d.mask->isConsistent());
  } catch (const Error&) {
  }
  return 0;
}
