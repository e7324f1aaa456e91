// `ellreloc observe`.

#include <CLI/CLI.hpp>
#include <cstdio>

#include "commands.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"

namespace ellreloc::cli {

CLI::App* addObserveCommand(CLI::App& app, ObserveArgs& a) {
  CLI::App* o = app.add_subcommand("observe", "fill each detection's `ellipse` and `regular` fields");
  o->add_option("--camera", a.camera, "camera.yaml or .json")->required()->check(CLI::ExistingFile);
  o->add_option("--detections", a.detections, "detections JSON")->required()->check(CLI::ExistingFile);
  o->add_option("--policy", a.policy, "solid, paper, bbox, mask or given (docs/observe.md)")->capture_default_str();
  o->add_option("--out", a.out, "output detections JSON")->required();
  o->footer("Example: ellreloc observe --camera C.yaml --detections D.json --policy solid --out O.json");
  return o;
}

ObservationPolicy parsePolicy(const std::string& name) {
  ObservationPolicy policy;
  if (parseObservationPolicy(name, &policy)) return policy;
  throw Error("--policy: unknown policy '" + name + "' (solid, paper, bbox, mask, given)");
}

void observe(const ObserveArgs& a, const Console& console) {
  checkPaths({{"--out", a.out}}, {{"--camera", a.camera}, {"--detections", a.detections}});
  const Intrinsics K = io::readCamera(a.camera);
  std::vector<DetectionFrame> frames = io::readDetections(a.detections);
  ObserveOptions options;
  options.policy = parsePolicy(a.policy);
  int observed = 0, regular = 0, dropped = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    for (Detection& d : frames[i].detections) {
      const ObserveResult r = observeDetection(d, K.width, K.height, options);
      if (!r.observation) {
        ++dropped;
        continue;
      }
      d.ellipse = r.observation->ellipse;
      d.regular = r.observation->regular.value_or(false);
      regular += d.regular.value();
      ++observed;
    }
    console.progress("observe", i + 1, frames.size());
  }
  console.endProgress();
  io::writeDetections(a.out, frames);
  if (!console.quiet)
    std::printf("wrote %s: %d ellipses (%d regular masks), %d detections without an observation\n", a.out.c_str(),
                observed, regular, dropped);
}

}  // namespace ellreloc::cli
