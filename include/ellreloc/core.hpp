#pragma once
/// \file core.hpp
/// The header-only geometry core (Eigen only): everything ellreloc::core provides.

#include "ellreloc/core/box.hpp"
#include "ellreloc/core/camera.hpp"
#include "ellreloc/core/distances.hpp"
#include "ellreloc/core/ellipse.hpp"
#include "ellreloc/core/ellipsoid.hpp"
#include "ellreloc/core/projection.hpp"
#include "ellreloc/error.hpp"
