#pragma once
/// \file core.hpp
/// The header-only core (Eigen and std only): everything ellreloc::core provides. Geometry
/// (ellipses, ellipsoids, cameras, poses, projection, distances), the minimal solvers that need
/// nothing else (Lambda Twist P3P, the generic RANSAC loop), and the plain data types every
/// component passes around (detections, masks, observations, depth images).

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/coco.hpp"
#include "ellreloc/core/depth_image.hpp"
#include "ellreloc/core/detection.hpp"
#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/distortion.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/ellipsoid.hpp"
#include "ellreloc/core/map_up.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/object_map.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/core/p3p.hpp"
#include "ellreloc/core/pose.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/core/ransac.hpp"
#include "ellreloc/core/rle.hpp"
#include "ellreloc/error.hpp"
