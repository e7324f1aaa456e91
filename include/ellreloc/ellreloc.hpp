#pragma once
/// \file ellreloc.hpp
/// Everything: the geometry core, observations, pose estimation, file I/O and the simulator.
/// Link ellreloc::ellreloc. (For the Eigen-only geometry alone, include ellreloc/core.hpp and
/// link ellreloc::core.)

#include "ellreloc/core.hpp"
#include "ellreloc/io/camera.hpp"
#include "ellreloc/io/detections.hpp"
#include "ellreloc/io/files.hpp"
#include "ellreloc/io/map.hpp"
#include "ellreloc/io/rgbd.hpp"
#include "ellreloc/io/trajectory.hpp"
#include "ellreloc/mapping/box_ellipsoid_builder.hpp"
#include "ellreloc/mapping/ellipsoid_builder.hpp"
#include "ellreloc/mapping/gravity.hpp"
#include "ellreloc/mapping/hungarian.hpp"
#include "ellreloc/mapping/mapper.hpp"
#include "ellreloc/mapping/object_tracker.hpp"
#include "ellreloc/mapping/voxel_object.hpp"
#include "ellreloc/observe/ellipse_fit.hpp"
#include "ellreloc/core/mask.hpp"
#include "ellreloc/core/observation.hpp"
#include "ellreloc/observe/observe.hpp"
#include "ellreloc/observe/regular_mask.hpp"
#include "ellreloc/core/rle.hpp"
#include "ellreloc/pose/object_relocalizer.hpp"
#include "ellreloc/core/p3p.hpp"
#include "ellreloc/core/ransac.hpp"
#include "ellreloc/pose/wasserstein_refiner.hpp"
#include "ellreloc/sim/noise.hpp"
#include "ellreloc/sim/render.hpp"
#include "ellreloc/sim/scene.hpp"
#include "ellreloc/sim/writer.hpp"
