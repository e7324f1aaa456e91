#pragma once
/// \file observation.hpp
/// What the relocalizer consumes: one detected object of the query image as an ellipse, with
/// its category, score and box.

#include <optional>

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/ellipse.hpp"

namespace ellreloc {

/// Where an observation's ellipse came from.
enum class EllipseSource {
  Box,    ///< inscribed in the detection box (OA-SLAM's model)
  Mask,   ///< fitted to the instance mask
  Given,  ///< taken from the detection file's `ellipse`
};

struct Observation {
  int category = 0;
  double score = 1.0;
  Ellipse ellipse;
  Box box;
  EllipseSource source = EllipseSource::Box;
  std::optional<bool> regular;  ///< the regular-mask verdict, when a mask was tested
  bool truncated = false;       ///< the box or mask touches the image border
};

/// An observation from a box: the inscribed ellipse. `truncated` is set when the box reaches
/// within `border_px` of the image border. nullopt for an invalid or empty box.
inline std::optional<Observation> observationFromBox(int category, double score, const Box& box, int width, int height,
                                                     double border_px = 2.0) {
  const auto e = Ellipse::inscribedInBox(box);
  if (!e) return std::nullopt;
  Observation o;
  o.category = category;
  o.score = score;
  o.ellipse = *e;
  o.box = box;
  o.source = EllipseSource::Box;
  o.truncated = box.nearImageBorder(width, height, border_px);
  return o;
}

}  // namespace ellreloc
