// The readers that take paths: camera YAML and JSON, TUM trajectories, association files.
#include "ellreloc/error.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ellreloc;
  for (const char* ext : {".yaml", ".json"}) {
    try {
      const Intrinsics K = io::readCamera(fuzz::writeScratch(data, size, ext));
      FUZZ_CHECK(K.isValid());  // a camera is valid or an error
    } catch (const Error&) {
    }
  }
  const std::string txt = fuzz::writeScratch(data, size, ".txt");
  try {
    for (const io::StampedPose& p : io::readTumTrajectory(txt)) FUZZ_CHECK(p.pose.isValid());
  } catch (const Error&) {
  }
  try {
    (void)io::readAssociations(txt);
  } catch (const Error&) {
  }
  return 0;
}
