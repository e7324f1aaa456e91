#include "ellreloc/observe/observe.hpp"

#include <cmath>

#include "ellreloc/core/mask.hpp"
#include "ellreloc/observe/ellipse_fit.hpp"

namespace ellreloc {

std::optional<Ellipse> fitMaskEllipse(const RleMask& rle, MaskFitMethod method, const RegularVerdict* verdict) {
  switch (method) {
    case MaskFitMethod::Moments: {
      const auto m = rleMoments(rle);
      return m ? momentEllipse(*m) : std::nullopt;
    }
    case MaskFitMethod::Direct:
      return fitEllipseDirect(rleOutline(rle));
    case MaskFitMethod::Hull:
      return hullEllipse(verdict && !verdict->hull.empty() ? verdict->hull : rleConvexHull(rle));
    case MaskFitMethod::Quadrilateral:
      if (!verdict || verdict->quad_vertices != 4) return std::nullopt;
      return projectivelyInscribedEllipse(verdict->corners);
  }
  return std::nullopt;
}

std::string ObserveOptions::validate() const {
  const RegularMaskOptions& m = regular;
  const std::pair<const char*, bool> checks[] = {
      {"border_px", border_px >= 0 && std::isfinite(border_px)},
      {"regular.min_solidity", m.min_solidity >= 0 && m.min_solidity <= 1},
      {"regular.min_fill", m.min_fill >= 0 && m.min_fill <= m.max_fill},
      {"regular.max_fill", std::isfinite(m.max_fill)},
      {"regular.noise_band_px", m.noise_band_px >= 0 && std::isfinite(m.noise_band_px)},
      {"regular.min_core_fill", m.min_core_fill >= 0 && m.min_core_fill <= 1},
      {"regular.max_corner_angle_deg", m.max_corner_angle_deg >= 0 && m.max_corner_angle_deg <= 180},
      {"regular.min_corner_angle_deg", m.min_corner_angle_deg >= 0 && m.min_corner_angle_deg <= m.max_corner_angle_deg},
      {"regular.min_pixels", m.min_pixels >= 0},
      {"regular.outline_tolerance", m.outline_tolerance >= 0 && m.outline_tolerance < 1},
      {"solid_min_solidity", solid_min_solidity >= 0 && solid_min_solidity <= 1},
  };
  for (const auto& [name, ok] : checks)
    if (!ok) return std::string("observe options: ") + name + " is out of range or not a number";
  if (lens)
    if (const std::string why = lens->whyNotUsable(); !why.empty()) return "observe options: lens: " + why;
  return "";
}

const char* toString(ObservationPolicy policy) {
  switch (policy) {
    case ObservationPolicy::Solid:
      return "solid";
    case ObservationPolicy::Paper:
      return "paper";
    case ObservationPolicy::Bbox:
      return "bbox";
    case ObservationPolicy::Mask:
      return "mask";
    case ObservationPolicy::Given:
      return "given";
  }
  return "unknown";
}

bool parseObservationPolicy(const std::string& name, ObservationPolicy* policy) {
  for (ObservationPolicy p : {ObservationPolicy::Solid, ObservationPolicy::Paper, ObservationPolicy::Bbox,
                              ObservationPolicy::Mask, ObservationPolicy::Given})
    if (name == toString(p)) return *policy = p, true;
  return false;
}

namespace {

/// observeDetection in the raw image, without the lens.
ObserveResult observeRaw(const Detection& d, int width, int height, const ObserveOptions& opt) {
  ObserveResult r;
  const Box image(-0.5, -0.5, width - 0.5, height - 0.5);
  if (!d.bbox.isValid() || !(d.bbox.width() > 0) || !(d.bbox.height() > 0) ||
      !(d.bbox.intersection(image).area() > 0)) {
    r.status = ObserveStatus::InvalidBox;
    return r;
  }
  auto box_obs = observationFromBox(d.category_id, d.score, d.bbox, width, height, opt.border_px);
  if (!box_obs) {
    r.status = ObserveStatus::InvalidBox;
    return r;
  }
  r.status = ObserveStatus::Ok;
  Observation obs = *box_obs;
  if (opt.policy == ObservationPolicy::Bbox) {
    r.observation = obs;
    return r;
  }
  if (opt.policy == ObservationPolicy::Given) {
    if (!d.ellipse || !d.ellipse->isValid()) {
      r.status = ObserveStatus::NoEllipse;
      return r;
    }
    obs.ellipse = *d.ellipse;
    obs.source = EllipseSource::Given;
    r.observation = obs;
    return r;
  }
  // Paper and Mask policies: use the mask when it is usable; a polygon stands for a mask.
  std::optional<RleMask> polygon_mask;
  if (!d.mask && d.polygon.size() >= 3) polygon_mask = polygonMask(d.polygon, height, width);
  const RleMask* mask = d.mask ? &*d.mask : polygon_mask ? &*polygon_mask : nullptr;
  if (!mask) {
    r.note = "no mask: box-inscribed ellipse";
    r.observation = obs;
    return r;
  }
  if (mask->height != height || mask->width != width) {
    r.note = "mask size " + std::to_string(mask->height) + "x" + std::to_string(mask->width) +
             " differs from the image " + std::to_string(height) + "x" + std::to_string(width) +
             ": box-inscribed ellipse";
    r.observation = obs;
    return r;
  }
  // Everything below works on the runs: the cost follows the object's size, not the image's.
  uint64_t ones = 0;
  for (size_t i = 1; i < mask->counts.size(); i += 2) ones += mask->counts[i];
  if (!mask->isConsistent() || ones == 0) {
    r.note = polygon_mask ? "polygon covers no pixel centre: box-inscribed ellipse"
                          : "empty or inconsistent mask: box-inscribed ellipse";
    r.observation = obs;
    return r;
  }
  const RegularVerdict verdict = testRegularMask(*mask, opt.regular);
  obs.regular = verdict.regular;
  obs.truncated = obs.truncated || verdict.touches_border;
  // The paper fits only its regular masks. The other policies choose the fit by what describes
  // the mask: the quadrilateral's ellipse when the quadrilateral test passes (also for a box seen
  // with a sliver of a second face, which the outline test turns down but whose quadrilateral
  // still describes it better than its hull does), else the hull's.
  const bool paper = opt.policy == ObservationPolicy::Paper;
  const bool quadrilateral_fit = paper ? verdict.regular : verdict.quadrilateral;
  const bool solid = opt.policy == ObservationPolicy::Solid && verdict.solidity >= opt.solid_min_solidity;
  if ((paper || opt.policy == ObservationPolicy::Solid) && !quadrilateral_fit && !solid) {
    r.observation = obs;
    return r;
  }
  const MaskFitMethod method = quadrilateral_fit ? opt.regular_fit : opt.irregular_fit;
  std::optional<Ellipse> fitted = fitMaskEllipse(*mask, method, &verdict);
  if (!fitted && method != MaskFitMethod::Moments) fitted = fitMaskEllipse(*mask, MaskFitMethod::Moments, &verdict);
  if (!fitted || !fitted->isValid()) {
    r.note = "ellipse fit failed: box-inscribed ellipse";
    r.observation = obs;
    return r;
  }
  obs.ellipse = *fitted;
  obs.source = EllipseSource::Mask;
  r.observation = obs;
  return r;
}

/// An observation of the raw image moved to the pinhole image: its box undistorted, and its
/// ellipse inscribed in that box when it came from the box (OA-SLAM's model, in the pinhole
/// image), else undistorted. The regular and border tests stay the raw image's.
bool undistort(const Lens& lens, Observation* o) {
  const std::optional<Box> box = lens.undistortBox(o->box);
  if (!box) return false;
  o->box = *box;
  const std::optional<Ellipse> e =
      o->source == EllipseSource::Box ? Ellipse::inscribedInBox(*box) : lens.undistortEllipse(o->ellipse);
  if (!e || !e->isValid()) return false;
  o->ellipse = *e;
  return true;
}

}  // namespace

ObserveResult observeDetection(const Detection& d, int width, int height, const ObserveOptions& opt) {
  ObserveResult r;
  if (std::string problem = opt.validate(); !problem.empty()) {
    r.status = ObserveStatus::InvalidOptions;
    r.note = std::move(problem);
    return r;
  }
  if (opt.lens && (opt.lens->intrinsics.width != width || opt.lens->intrinsics.height != height)) {
    r.status = ObserveStatus::InvalidOptions;
    r.note = "observe options: lens: its intrinsics are of a " + std::to_string(opt.lens->intrinsics.width) + "x" +
             std::to_string(opt.lens->intrinsics.height) + " image, the detections of a " + std::to_string(width) +
             "x" + std::to_string(height) + " one";
    return r;
  }
  r = observeRaw(d, width, height, opt);
  if (opt.lens && r.observation && !undistort(*opt.lens, &*r.observation)) {
    r.status = ObserveStatus::InvalidBox;
    r.observation.reset();
    r.note = "the box reaches where the lens's distortion cannot be undone";
  }
  return r;
}

std::vector<Observation> observeDetections(const std::vector<Detection>& detections, int width, int height,
                                           const ObserveOptions& options) {
  std::vector<Observation> out;
  for (const Detection& d : detections)
    if (ObserveResult r = observeDetection(d, width, height, options); r.observation) out.push_back(*r.observation);
  return out;
}

}  // namespace ellreloc
