#pragma once
/// \file observe.hpp
/// Turns a detection (box, optional mask or ellipse) into an observation ellipse. The paper's
/// relocalization fits an ellipse to a "regular" mask (a convex quadrilateral) and takes the
/// ellipse inscribed in the box of any other detection. By default a mask its four-corner
/// quadrilateral describes (regular, or a box seen with a sliver of a second face) gets the
/// quadrilateral's ellipse, and another solid mask (the silhouette of a convex object: a box
/// seen on two or three faces, a cylinder; a chair seen whole) the hull fit.

#include <optional>
#include <string>
#include <vector>

#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/distortion.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/observe/regular_mask.hpp"

namespace ellreloc {

enum class ObservationPolicy {
  Paper,  ///< regular mask -> mask fit, otherwise the box-inscribed ellipse
  Bbox,   ///< always the box-inscribed ellipse (OA-SLAM)
  Mask,   ///< fit the mask whenever there is one
  Given,  ///< the detection's own `ellipse` field
  /// a mask that passes the quadrilateral test (RegularVerdict::quadrilateral) -> its
  /// quadrilateral's ellipse; another solid mask (ObserveOptions::solid_min_solidity) -> its
  /// hull fit; otherwise the box-inscribed ellipse
  Solid,
};

/// Name <-> policy: "solid", "paper", "bbox", "mask", "given".
const char* toString(ObservationPolicy policy);
bool parseObservationPolicy(const std::string& name, ObservationPolicy* policy);

/// How an ellipse is fitted to a mask.
enum class MaskFitMethod {
  Moments,        ///< same second moments as the mask (from the RLE runs, no decoding)
  Direct,         ///< direct least squares on the outline, image-border points dropped
  Quadrilateral,  ///< regular masks: the projectively inscribed ellipse of the quadrilateral
  Hull,           ///< the inscribed ellipsoid's image from the mask's convex hull (hullEllipse)
};

struct ObserveOptions {
  ObservationPolicy policy = ObservationPolicy::Solid;
  /// For regular masks (Paper), for masks that pass the quadrilateral test (Mask and Solid).
  MaskFitMethod regular_fit = MaskFitMethod::Quadrilateral;
  MaskFitMethod irregular_fit = MaskFitMethod::Hull;  ///< for other masks (policies Mask and Solid)
  RegularMaskOptions regular;
  /// Policy Solid: any other mask that covers at least this share of its convex hull
  /// (RegularVerdict::solidity) gets its hull fit. The silhouette of a convex solid fills its
  /// hull; that of a composite object seen whole (a chair, a plant: about half to four fifths)
  /// has a hull close to its cuboid's silhouette, and the hull fit estimates the image of the
  /// object's ellipsoid better than the box does for both. A mask covering less than half its
  /// hull is mostly gaps (thin parts, fragments of a partly hidden object): it keeps the box.
  double solid_min_solidity = 0.5;
  double border_px = 2.0;  ///< a box this close to the image border is flagged truncated
  /// The camera of the raw image the detections were made on, when its lens distorts: each
  /// observation is made in the raw image (mask fits, the regular and border tests), then
  /// moved to the pinhole image of the same intrinsics that the map's projections assume: its
  /// box undistorted (Lens::undistortBox) and its ellipse inscribed in that box, or undistorted
  /// when it came from a mask or the detection file. Unset: the detections are taken as pinhole.
  std::optional<Lens> lens;

  /// Empty when every threshold is finite and in range, else one line naming the first that
  /// is not; observeDetection then answers InvalidOptions.
  std::string validate() const;
};

enum class ObserveStatus {
  Ok,
  InvalidBox,      ///< NaN, empty, or wholly outside the image: no observation
  NoEllipse,       ///< policy Given without an `ellipse`, or an invalid one: no observation
  InvalidOptions,  ///< ObserveOptions::validate() failed (`note` names the field): no observation
};

struct ObserveResult {
  ObserveStatus status = ObserveStatus::InvalidBox;
  std::optional<Observation> observation;
  /// Why the mask was not used when the policy wanted it (size mismatch, empty mask, fit
  /// failed); the observation then falls back to the box-inscribed ellipse.
  std::string note;
};

/// Observes one detection of an image of width x height pixels.
ObserveResult observeDetection(const Detection& detection, int width, int height, const ObserveOptions& options = {});

/// The observations of one image's detections: observeDetection on each, in order, those that
/// give none (an invalid box, no ellipse) left out.
std::vector<Observation> observeDetections(const std::vector<Detection>& detections, int width, int height,
                                           const ObserveOptions& options = {});

/// Fits an ellipse to a run-length mask with the given method (no decoding); `verdict` is
/// needed by Quadrilateral, and Hull takes the mask's hull from it when it has one.
std::optional<Ellipse> fitMaskEllipse(const RleMask& rle, MaskFitMethod method, const RegularVerdict* verdict);

}  // namespace ellreloc
