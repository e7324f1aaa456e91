// End-to-end tests of the command line's pictures: per-frame overlays, the comparison plot
// (PNG and SVG), the per-frame CSV, and help that describes every option.

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <regex>

#include "cli/cli_run.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/overlay.hpp"
#include "ellreloc/io/trajectory.hpp"

namespace {

using namespace ellreloc;
using namespace ellreloc::test::cli;

/// A small simulated scene shared by the tests of this file (the perturbed true map is its map).
class Pictures : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    scene_ = dir_->path("scene");
    const CliRun r =
        run("simulate --preset office --seed 3 --mapping-frames 4 --query-frames 8 --out " + scene_, *dir_);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string relocalizeArgs(const std::string& detections) {
    return "relocalize --camera " + scene_ + "/camera.yaml --map " + scene_ + "/map_perturbed.json --detections " +
           detections;
  }
  static test::TempDir* dir_;
  static std::string scene_;
};
test::TempDir* Pictures::dir_ = nullptr;
std::string Pictures::scene_;

bool orange(const cv::Vec3b& bgr) { return bgr[2] > 200 && bgr[1] > 90 && bgr[1] < 190 && bgr[0] < 90; }

/// Share of points on an ellipse's outline with an orange pixel within 1 px.
double orangeShare(const cv::Mat& img, const Ellipse& e) {
  int hits = 0, points = 0;
  for (const Eigen::Vector2d& p : e.sampleBoundary(64)) {
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    if (x < 2 || y < 2 || x >= img.cols - 2 || y >= img.rows - 2) continue;
    ++points;
    bool hit = false;
    for (int dy = -1; dy <= 1 && !hit; ++dy)
      for (int dx = -1; dx <= 1 && !hit; ++dx) hit = orange(img.at<cv::Vec3b>(y + dy, x + dx));
    hits += hit;
  }
  return points > 0 ? static_cast<double>(hits) / points : 0.0;
}

TEST_F(Pictures, OverlaysDrawTheMapWhereTheReturnedPoseProjectsIt) {
  test::TempDir dir;
  const std::string overlays = dir.path("overlays");
  CliRun r = run(relocalizeArgs(scene_ + "/query/detections.json") + " --out " + dir.path("poses.txt") +
                     " --reference " + scene_ + "/query/groundtruth.txt --overlays " + overlays,
                 dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const Intrinsics K = io::readCamera(scene_ + "/camera.yaml");
  const ObjectMap map = io::readMap(scene_ + "/map_perturbed.json");
  const std::vector<io::StampedPose> poses = io::readTumTrajectory(dir.path("poses.txt"));
  ASSERT_GE(poses.size(), 4u);
  EXPECT_EQ(std::distance(fs::directory_iterator(overlays), fs::directory_iterator()), 8);
  for (const io::StampedPose& p : poses) {
    const cv::Mat img = cv::imread(overlays + "/" + p.stamp + ".png");
    ASSERT_FALSE(img.empty()) << p.stamp;
    ASSERT_EQ(img.cols, K.width);
    ASSERT_EQ(img.rows, K.height);
    // Every map object well inside the image at the returned pose is outlined in orange there.
    int checked = 0;
    for (const MapObject& o : map.objects) {
      const Projection proj = project(o.ellipsoid, K, p.pose);
      if (!proj) continue;
      const Box b = proj.ellipse.boundingBox();
      if (b.x1 < 5 || b.y1 < 40 || b.x2 > K.width - 5 || b.y2 > K.height - 20 || proj.ellipse.axes()(1) < 6) continue;
      EXPECT_GT(orangeShare(img, proj.ellipse), 0.6) << p.stamp << " object " << o.id;
      ++checked;
    }
    EXPECT_GT(checked, 0) << p.stamp;
  }
  // The frame's own image is the background when its file resolves; else a blank canvas.
  const std::string moved = dir.path("elsewhere/detections.json");
  fs::create_directories(dir.path("elsewhere"));
  fs::copy_file(scene_ + "/query/detections.json", moved);
  r = run(relocalizeArgs(moved) + " --out " + dir.path("poses2.txt") + " --overlays " + dir.path("blank"), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string name = "/" + poses[0].stamp + ".png";
  const cv::Mat on_image = cv::imread(overlays + name), blank = cv::imread(dir.path("blank") + name);
  const cv::Vec3b background = blank.at<cv::Vec3b>(K.height / 2, 2);
  EXPECT_EQ(background, cv::Vec3b(245, 245, 245));
  int differing = 0;
  for (int y = 0; y < K.height; y += 8)
    for (int x = 0; x < K.width; x += 8) differing += on_image.at<cv::Vec3b>(y, x) != blank.at<cv::Vec3b>(y, x);
  EXPECT_GT(differing, K.width * K.height / 64 / 4);  // the rendered image shows through
}

TEST_F(Pictures, OverlaysTakeJpegBackgroundsAndNameAnUnreadableOne) {
  test::TempDir dir;
  std::ifstream in(scene_ + "/query/detections.json");
  const std::string detections((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::smatch first;
  ASSERT_TRUE(std::regex_search(detections, first, std::regex("rgb/([0-9.]+)\\.png")));
  const std::string stamp = first[1];
  // The first frame's image as a JPEG beside a copy of the detections that names it.
  fs::create_directories(dir.path("jpeg/rgb"));
  const cv::Mat image = cv::imread(scene_ + "/query/rgb/" + stamp + ".png");
  ASSERT_FALSE(image.empty());
  ASSERT_TRUE(cv::imwrite(dir.path("jpeg/rgb/" + stamp + ".jpg"), image, {cv::IMWRITE_JPEG_QUALITY, 95}));
  const std::string as_jpeg =
      std::regex_replace(detections, std::regex("rgb/" + stamp + "\\.png"), "rgb/" + stamp + ".jpg");
  std::ofstream(dir.path("jpeg/detections.json")) << as_jpeg;
  CliRun r = run(relocalizeArgs(scene_ + "/query/detections.json") + " --out " + dir.path("a.txt") + " --overlays " +
                     dir.path("png_overlays"),
                 dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(relocalizeArgs(dir.path("jpeg/detections.json")) + " --out " + dir.path("b.txt") + " --overlays " +
              dir.path("jpeg_overlays"),
          dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const cv::Mat over_png = cv::imread(dir.path("png_overlays/" + stamp + ".png"));
  const cv::Mat over_jpeg = cv::imread(dir.path("jpeg_overlays/" + stamp + ".png"));
  ASSERT_FALSE(over_png.empty());
  ASSERT_EQ(over_png.size(), over_jpeg.size());
  // The same picture up to the JPEG's error (lightened to 0.6 of it by the overlay): a few
  // pixels at colour edges are far off (chroma subsampling: 0.3% here), where colour channels
  // read in the wrong order put 2% of them so, every object's pixels.
  cv::Mat off;
  cv::absdiff(over_png, over_jpeg, off);
  off = off.reshape(1, static_cast<int>(off.total()));
  cv::reduce(off, off, 1, cv::REDUCE_MAX);
  EXPECT_LT(cv::countNonZero(off > 24) / static_cast<double>(off.total()), 0.01);
  // A background that is no image: one line naming the file, no overlay for it.
  fs::create_directories(dir.path("bad/rgb"));
  std::ofstream(dir.path("bad/rgb/" + stamp + ".png")) << "not an image";
  std::ofstream(dir.path("bad/detections.json")) << detections;
  r = run(relocalizeArgs(dir.path("bad/detections.json")) + " --out " + dir.path("c.txt") + " --overlays " +
              dir.path("bad_overlays"),
          dir);
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("rgb/" + stamp + ".png: not a PNG or JPEG image"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir.path("bad_overlays/" + stamp + ".png")));
}

// With a lens, the background (a raw image) is undistorted as the observations drawn over it
// were: a spot near the corner of a raw fr2 image lands where the lens's inverse puts it.
TEST(Overlays, ARawBackgroundIsUndistortedWithTheLens) {
  test::TempDir dir;
  const Intrinsics K(520.90862, 521.007327, 325.141442, 249.701764, 640, 480);
  const Lens lens{K, {0.231222, -0.784899, -0.003257, -0.000105, 0.917205}};
  cv::Mat raw(K.height, K.width, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::rectangle(raw, cv::Point(57, 47), cv::Point(63, 53), cv::Scalar(255, 255, 255), cv::FILLED);
  ASSERT_TRUE(cv::imwrite(dir.path("raw.png"), raw));
  const auto spot = [&](const Lens* l) {
    io::writeOverlay(dir.path("overlay.png"), K, ObjectMap{}, io::OverlayContent{}, dir.path("raw.png"), l);
    const cv::Mat img = cv::imread(dir.path("overlay.png"));
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int n = 0;
    for (int y = 20; y < 90; ++y)  // around the spot (the overlay draws a legend elsewhere)
      for (int x = 20; x < 110; ++x)
        if (img.at<cv::Vec3b>(y, x)[1] > 200) sum += Eigen::Vector2d(x, y), ++n;  // white, lightened
    return n > 0 ? Eigen::Vector2d(sum / n) : Eigen::Vector2d(-1, -1);
  };
  const Eigen::Vector2d expected = *lens.undistortPixel({60.0, 50.0});
  EXPECT_GT((expected - Eigen::Vector2d(60, 50)).norm(), 5.0);
  EXPECT_LT((spot(&lens) - expected).norm(), 1.0);
  EXPECT_LT((spot(nullptr) - Eigen::Vector2d(60, 50)).norm(), 0.5);
  // The resampling is kept from one picture to the next of the same lens: another lens between
  // two pictures of the first gets its own, and the first its own again.
  const Lens milder{K, {0.1, -0.2, 0.0, 0.0, 0.1}};
  const Eigen::Vector2d expected_milder = *milder.undistortPixel({60.0, 50.0});
  EXPECT_GT((expected_milder - expected).norm(), 3.0);
  EXPECT_LT((spot(&milder) - expected_milder).norm(), 1.0);
  EXPECT_LT((spot(&lens) - expected).norm(), 1.0);
}

TEST_F(Pictures, ComparisonPlotsAndPerFrameCsvCoverEveryMethodAndFrame) {
  test::TempDir dir;
  for (const std::string method : {"ours", "oa-slam"}) {
    const CliRun r = run(relocalizeArgs(scene_ + "/query/detections.json") + " --method " + method + " --out " +
                             dir.path(method + ".txt"),
                         dir);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  const std::string common = "evaluate --groundtruth " + scene_ + "/query/groundtruth.txt --detections " + scene_ +
                             "/query/detections.json --estimate " + dir.path("ours.txt") + ":ours --estimate " +
                             dir.path("oa-slam.txt") + ":OA-SLAM --map " + scene_ + "/map_perturbed.json";
  CliRun r = run(common + " --plot " + dir.path("plot.svg") + " --per-frame " + dir.path("frames.csv"), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| ours |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| OA-SLAM |"), std::string::npos) << r.out;
  const std::string svg = readFile(dir.path("plot.svg"));
  for (const std::string text :
       {">position error (cm)</text>", ">rotation error (deg)</text>", ">Top view</text>", ">valid: &lt; 30 cm</text>",
        "ours (", "OA-SLAM (", ">x (m)</text>", "map objects, coloured by category"})
    EXPECT_NE(svg.find(text), std::string::npos) << text;
  EXPECT_EQ(svg.rfind("</svg>"), svg.size() - 7);
  r = run(common + " --plot " + dir.path("plot.png"), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const cv::Mat png = cv::imread(dir.path("plot.png"));
  EXPECT_EQ(png.cols, 1500);
  EXPECT_EQ(png.rows, 540);
  // One CSV row per frame and method; its valid rows agree with the table.
  const std::string csv = readFile(dir.path("frames.csv"));
  EXPECT_EQ(lines(csv), 1 + 2 * 8);
  const std::regex row_re(R"(\| [-0-9.]+ \| [-0-9.]+ \| ([0-9.]+) \| (\d+) / 8 \| ours \|)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, row_re)) << r.out;
  int valid = 0, posed = 0;
  std::istringstream rows(csv);
  for (std::string line; std::getline(rows, line);) {
    if (line.find(",ours,") == std::string::npos) continue;
    valid += line.find(",ours,valid,") != std::string::npos;
    posed += line.find(",ours,no pose,") == std::string::npos;
  }
  EXPECT_EQ(valid, static_cast<int>(std::lround(std::stod(m[1]) * 8 / 100)));
  EXPECT_EQ(posed, std::stoi(m[2]));
  r = run("evaluate --groundtruth " + scene_ + "/query/groundtruth.txt --estimate " + dir.path("ours.txt") +
              ":same --estimate " + dir.path("oa-slam.txt") + ":same",
          dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("two methods are labelled 'same'"), std::string::npos) << r.err;
}

TEST(CliHelp, EveryOptionOfEverySubcommandIsDescribed) {
  test::TempDir dir;
  for (const std::string sub : {"simulate", "observe", "map", "relocalize", "evaluate", "report", "demo"}) {
    const CliRun r = run(sub + " --help", dir);
    ASSERT_EQ(r.code, 0) << sub;
    EXPECT_EQ(r.out.find("FORMATS.md"), std::string::npos) << sub << ": cites a file users do not have";
    std::istringstream help(r.out);
    std::vector<std::string> lines_of_help;
    for (std::string line; std::getline(help, line);) lines_of_help.push_back(line);
    int options = 0;
    for (size_t i = 0; i < lines_of_help.size(); ++i) {
      const std::string& line = lines_of_help[i];
      if (line.rfind("  -", 0) != 0) continue;
      ++options;
      // CLI11 puts the description at column 30, or on the next line under a long option.
      const bool same_line =
          line.size() > 30 && line[29] == ' ' && line.find_first_not_of(' ', 30) != std::string::npos;
      const bool next_line = i + 1 < lines_of_help.size() && lines_of_help[i + 1].rfind(std::string(30, ' '), 0) == 0 &&
                             lines_of_help[i + 1].find_first_not_of(' ') != std::string::npos;
      EXPECT_TRUE(same_line || next_line) << sub << ": " << line;
    }
    EXPECT_GE(options, 2) << sub;
  }
}

/// The path of a Chromium-family browser, or "" (scripts/install-deps.sh installs Debian's).
std::string browser() {
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"}) {
    const std::string cmd = std::string("command -v ") + name + " >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return name;
  }
  return "";
}

TEST_F(Pictures, TheReportRendersInABrowserWithEveryFrame) {
  test::TempDir dir;
  CliRun r = run(relocalizeArgs(scene_ + "/query/detections.json") + " --out " + dir.path("ours.txt") + " --overlays " +
                     dir.path("overlays"),
                 dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(relocalizeArgs(scene_ + "/query/detections.json") + " --method oa-slam --out " + dir.path("oa.txt"), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("report --groundtruth " + scene_ + "/query/groundtruth.txt --detections " + scene_ +
              "/query/detections.json --estimate " + dir.path("ours.txt") + ":ours --estimate " + dir.path("oa.txt") +
              ":OA-SLAM --map " + scene_ + "/map_perturbed.json --overlays " + dir.path("overlays") +
              " --worst 3 --out " + dir.path("report.html"),
          dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string page = readFile(dir.path("report.html"));
  // Self-contained: nothing fetched from elsewhere.
  for (const std::string outside : {"src=\"http", "href=\"http", "url(", "src=\"/", "src=\"file:", "<link"})
    EXPECT_EQ(page.find(outside), std::string::npos) << outside;
  size_t images = 0;
  for (size_t at = page.find("data:image/png;base64,"); at != std::string::npos;
       at = page.find("data:image/png;base64,", at + 1))
    ++images;
  EXPECT_EQ(images, 3u);
  EXPECT_NE(page.find("<svg"), std::string::npos);

  const std::string chromium = browser();
  if (chromium.empty()) GTEST_SKIP() << "no chromium to render the report (scripts/install-deps.sh installs it)";
  // The page's script counts the rows of the frame table once it has run without error.
  const std::string dom = dir.path("dom.html"), log = dir.path("browser.log");
  const std::string cmd =
      "timeout 120 " + chromium + " --headless --no-sandbox --disable-gpu --disable-dev-shm-usage " +
      "--user-data-dir=" + dir.path("profile") + " --enable-logging=stderr --v=0 --dump-dom file://" +
      dir.path("report.html") + " >" + dom + " 2>" + log;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << readFile(log);
  const std::string rendered = readFile(dom);
  EXPECT_NE(rendered.find("data-frames=\"8\""), std::string::npos) << rendered.substr(0, 400) << "\n" << readFile(log);
  EXPECT_EQ(readFile(log).find("Uncaught"), std::string::npos) << readFile(log);
}

}  // namespace
