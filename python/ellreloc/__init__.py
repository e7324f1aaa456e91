"""ellreloc: object-based camera relocalization with ellipses and ellipsoids.

Detections of one image become ellipses (observe), are matched to a map of 3D ellipsoids and
give the camera pose (ObjectRelocalizer); Mapper builds such maps from RGB-D keyframes and
instance masks, or from boxes and poses. Poses are world->camera (Pose.T_cw); TUM files and
RelocalizationResult.T_wc are camera->world. docs/python.md walks through it.
"""

import sys as _sys  # private names: `dir(ellreloc)` lists the library only

try:
    import numpy as _numpy  # noqa: F401  (the extension passes numpy arrays: without it, it cannot load)
except ImportError as missing:
    raise ImportError(f"ellreloc needs numpy, which {_sys.executable} cannot import; the package was built for "
                      f"@Python3_EXECUTABLE@ (Python @Python3_VERSION@): run that interpreter, or install numpy "
                      f"for this one") from missing

from ._ellreloc import *  # noqa: F401,F403,E402  (the C++ library's classes and functions)
from ._ellreloc import sim  # noqa: F401,E402

__version__ = "@PROJECT_VERSION@"
