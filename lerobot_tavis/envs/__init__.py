"""Everything that simulates. Importing any module below this package loads MuJoCo, except the registries
(`tasks.catalog`, `robots` itself, `modes`: see `lerobot_tavis.registry`).

MuJoCo picks its OpenGL backend when it is first imported, so the default (headless EGL: Mesa llvmpipe on a CPU,
the GPU where there is one) is chosen here, before any submodule imports mujoco. A value set by the user wins.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
