// What fuzzing found (docs/reliability.md), kept as ordinary tests so that it stays fixed.
#include <gtest/gtest.h>

#include <cmath>

#include "ellreloc/core/distances.hpp"
#include "ellreloc/error.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/mapping/voxel_object.hpp"
#include "ellreloc/core/rle.hpp"

namespace ellreloc {
namespace {

// nlohmann throws out_of_range (not parse_error) for a number too large for a double; it
// escaped the readers as a foreign exception.
TEST(FuzzFindings, JsonNumberOverflowIsAnError) {
  EXPECT_THROW(io::parseMapJson("{\"objects\": [8888888888e8888]}", "m.json"), Error);
  EXPECT_THROW(io::parseDetectionsJson("[{\"file_name\": 1e99999}]", "d.json"), Error);
}

// A compressed RLE group of 13 characters shifted a 64-bit value by 60 and 65 bits (undefined
// behaviour); groups longer than 8 characters are now malformed.
TEST(FuzzFindings, OverlongRleGroupsAreMalformed) {
  EXPECT_FALSE(decodeRleString(std::string(13, 'o')));  // 'o' = 63: continuation bit and all ones
  EXPECT_FALSE(decodeRleString(std::string(9, 'o') + "0"));
  EXPECT_EQ(decodeRleString(encodeRleString({0, 4294967295u, 1})), std::vector<uint32_t>({0, 4294967295u, 1}));
}

// Valid ellipses of absurd size overflowed W2 and the level-set distance to NaN; the distance
// between them is now +infinity.
TEST(FuzzFindings, DistancesOfHugeEllipsesAreInfiniteNotNaN) {
  const Ellipse a({2.4e-201, 2.4e109}, {1e-80, 1.4e-8}, 5e-195);
  const Ellipse b({5.9e10, -2.9e-217}, {1.1e-151, 1.1e186}, 5.2e-14);
  ASSERT_TRUE(a.isValid() && b.isValid());
  EXPECT_FALSE(std::isnan(wasserstein2(a, b)));
  EXPECT_FALSE(std::isnan(bhattacharyya(a, b)));
  EXPECT_FALSE(std::isnan(levelSetDistance(a, b, 4)));
  EXPECT_GE(wasserstein2(a, b), 0.0);
}

// A detection box far outside the image (finite, 8e136 pixels) overflowed the int cast of its
// pixel bounds when voxel mapping took the box as the mask (undefined behaviour); it gives an
// empty mask, and a box that only reaches past the image is cut to it.
TEST(FuzzFindings, BoxMasksFarOutsideTheImageAreEmpty) {
  EXPECT_EQ(maskFromBox(Box(8.2e136, 1.0, 9e136, 20.0), 64, 48).count(), 0);
  EXPECT_EQ(maskFromBox(Box(-1e200, -1e200, -1e199, -1e199), 64, 48).count(), 0);
  const BinaryMask cut = maskFromBox(Box(-1e200, 10.0, 1e200, 12.0), 64, 48);
  EXPECT_EQ(cut.count(), 64 * 3);
  EXPECT_EQ(cut.x0, 0);
  EXPECT_EQ(cut.width, 64);
}

}  // namespace
}  // namespace ellreloc
