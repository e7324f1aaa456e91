#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "ellreloc/error.hpp"
#include "ellreloc/io/image_codec.hpp"

using namespace ellreloc;

// The codec is checked against OpenCV's imgcodecs, which the library no longer links but the
// tests do: every image encoded here must decode there to the same pixels, and the reverse.
namespace {

cv::Mat randomImage(int rows, int cols, int type, unsigned seed) {
  cv::Mat m(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

std::string opencvEncode(const cv::Mat& m, const std::string& ext, std::vector<int> params = {}) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(ext, m, bytes, params));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat opencvDecode(const std::string& bytes, int flags) {
  return cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())), flags);
}

cv::Mat asMat(const io::DecodedImage& d) {
  const int type = d.format == io::PixelFormat::Grey8  ? CV_8UC1
                   : d.format == io::PixelFormat::Bgr8 ? CV_8UC3
                                                       : CV_16UC1;
  return cv::Mat(d.height, d.width, type, const_cast<uint8_t*>(d.pixels.data())).clone();
}

io::PixelFormat formatOf(int type) {
  return type == CV_8UC1 ? io::PixelFormat::Grey8 : type == CV_8UC3 ? io::PixelFormat::Bgr8 : io::PixelFormat::Grey16;
}

bool samePixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

std::string expectError(const std::string& bytes, const std::string& name, io::DecodeAs as) {
  try {
    io::decodeImage(bytes, name, as);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "decoded " << name;
  return "";
}

}  // namespace

TEST(ImageCodec, PngsItWritesDecodeInOpenCvToTheSamePixels) {
  for (int type : {CV_8UC1, CV_8UC3, CV_16UC1})
    for (int compression : {0, 1, 9}) {
      const cv::Mat image = randomImage(37, 53, type, 7u + compression);
      // A view into a wider image: rows are not packed, and the stride is honoured.
      cv::Mat wide = randomImage(37, 70, type, 3);
      image.copyTo(wide.colRange(5, 58));
      const cv::Mat view = wide.colRange(5, 58);
      const std::string png = io::encodePng(view.data, view.cols, view.rows, formatOf(type), view.step, compression);
      EXPECT_TRUE(samePixels(opencvDecode(png, cv::IMREAD_UNCHANGED), image)) << type << " " << compression;
      // And back through the library's own decoder.
      EXPECT_TRUE(samePixels(asMat(io::decodeImage(png, "own.png", io::DecodeAs::Stored)), image)) << type;
    }
}

TEST(ImageCodec, DecodesOpenCvPngsAsStoredOrAsColour) {
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3}) {
    const cv::Mat image = randomImage(29, 41, type, 11u + type);
    const std::string png = opencvEncode(image, ".png");
    // Stored: grey stays grey at its depth; alpha is dropped; 16-bit colour becomes 8-bit, as
    // OpenCV's own 8-bit colour decoding makes it.
    const cv::Mat stored = asMat(io::decodeImage(png, "a.png", io::DecodeAs::Stored));
    cv::Mat expected;
    if (type == CV_8UC1 || type == CV_16UC1 || type == CV_8UC3)
      expected = image;
    else
      expected = opencvDecode(png, cv::IMREAD_COLOR);
    EXPECT_TRUE(samePixels(stored, expected)) << type;
    // As colour, every image is 8-bit BGR, as OpenCV's IMREAD_COLOR gives it.
    const cv::Mat colour = asMat(io::decodeImage(png, "a.png", io::DecodeAs::Bgr8));
    EXPECT_TRUE(samePixels(colour, opencvDecode(png, cv::IMREAD_COLOR))) << type;
  }
}

TEST(ImageCodec, DecodesJpegsAsOpenCvDoes) {
  // A smooth image, as photographs are, so that the JPEG keeps its content.
  cv::Mat image(48, 64, CV_8UC3);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(4 * x), static_cast<uchar>(5 * y), 128);
  const std::string jpeg = opencvEncode(image, ".jpg", {cv::IMWRITE_JPEG_QUALITY, 90});
  const cv::Mat ours = asMat(io::decodeImage(jpeg, "a.jpg", io::DecodeAs::Bgr8));
  const cv::Mat theirs = opencvDecode(jpeg, cv::IMREAD_COLOR);
  ASSERT_EQ(ours.size(), theirs.size());
  // Both through libjpeg's default decoding: the same pixels up to the rounding of its colour
  // conversion, and close to the original.
  EXPECT_LE(cv::norm(ours, theirs, cv::NORM_INF), 1.0);
  EXPECT_LT(cv::norm(ours, image, cv::NORM_L1) / image.total() / 3, 3.0);
  // A grey JPEG stays grey when decoded as stored, and is expanded as colour.
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  const std::string grey_jpeg = opencvEncode(grey, ".jpg");
  const io::DecodedImage stored = io::decodeImage(grey_jpeg, "g.jpg", io::DecodeAs::Stored);
  EXPECT_EQ(stored.format, io::PixelFormat::Grey8);
  EXPECT_LE(cv::norm(asMat(stored), opencvDecode(grey_jpeg, cv::IMREAD_GRAYSCALE), cv::NORM_INF), 1.0);
  EXPECT_EQ(io::decodeImage(grey_jpeg, "g.jpg", io::DecodeAs::Bgr8).format, io::PixelFormat::Bgr8);
}

TEST(ImageCodec, BadBytesGiveOneErrorNamingTheInput) {
  EXPECT_NE(expectError("", "empty.png", io::DecodeAs::Stored).find("empty.png: not a PNG or JPEG image"),
            std::string::npos);
  EXPECT_NE(expectError("GIF89a....", "a.gif", io::DecodeAs::Bgr8).find("not a PNG or JPEG"), std::string::npos);
  const std::string png = opencvEncode(randomImage(40, 40, CV_8UC3, 1), ".png");
  const std::string jpeg = opencvEncode(randomImage(40, 40, CV_8UC3, 1), ".jpg");
  // Truncated anywhere, or with a byte flipped inside the header or the data: an error, never a crash.
  for (size_t cut : {size_t{9}, size_t{30}, png.size() / 2, png.size() - 13}) {
    const std::string e = expectError(png.substr(0, cut), "cut.png", io::DecodeAs::Stored);
    EXPECT_EQ(e.rfind("cut.png: cannot decode PNG image (", 0), 0u) << e;
  }
  std::string damaged = png;
  damaged[26] ^= 0x40;  // the compression method in IHDR: its CRC no longer matches
  EXPECT_NE(expectError(damaged, "crc.png", io::DecodeAs::Stored).find("crc.png: cannot decode PNG"),
            std::string::npos);
  for (size_t cut : {size_t{3}, size_t{20}}) {
    const std::string e = expectError(jpeg.substr(0, cut), "cut.jpg", io::DecodeAs::Bgr8);
    EXPECT_EQ(e.rfind("cut.jpg: cannot decode JPEG image (", 0), 0u) << e;
  }
  // An image larger than the limit is refused from its header.
  try {
    io::decodeImage(png, "big.png", io::DecodeAs::Stored, 1000);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("big.png: declares a 40x40 image"), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::decodeImage(jpeg, "big.jpg", io::DecodeAs::Bgr8, 1000), Error);
}

TEST(ImageCodec, EncodingRefusesWhatItCannotWrite) {
  const std::vector<uint8_t> pixels(12, 0);
  EXPECT_THROW(io::encodePng(pixels.data(), 0, 4, io::PixelFormat::Grey8, 4), Error);
  EXPECT_THROW(io::encodePng(pixels.data(), 4, 3, io::PixelFormat::Bgr8, 4), Error);  // rows shorter than 4 pixels
  EXPECT_THROW(io::encodePng(nullptr, 2, 2, io::PixelFormat::Grey8, 2), Error);
  EXPECT_THROW(io::encodePng(pixels.data(), 2, 2, io::PixelFormat::Grey8, 2, 10), Error);
  EXPECT_EQ(io::bytesPerPixel(io::PixelFormat::Grey16), 2);
}
