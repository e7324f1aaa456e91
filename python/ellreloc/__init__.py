"""ellreloc: object-based camera relocalization with ellipses and ellipsoids.

Detections of one image become ellipses (observe), are matched to a map of 3D ellipsoids and
give the camera pose (ObjectRelocalizer); Mapper builds such maps from RGB-D keyframes and
instance masks, or from boxes and poses. Poses are world->camera (Pose.T_cw); TUM files and
RelocalizationResult.T_wc are camera->world. docs/python.md walks through it.
"""

from ._ellreloc import *  # noqa: F401,F403  (the C++ library's classes and functions)
from ._ellreloc import sim  # noqa: F401

__version__ = "@PROJECT_VERSION@"
