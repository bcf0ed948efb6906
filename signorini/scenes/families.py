"""The built-in scene families, registered by name, and the registry's look-ups.

A new family is one module with a ``FAMILY`` and one line below (or a call
to :func:`~signorini.scenes.registry.register` from anywhere).
"""

from __future__ import annotations

from signorini.problem.files import is_problem_file
from signorini.scenes import (block, hertz_cylinder, hertz_sphere, hertz_sphere_3d, hertz_two_cylinders,
                              hertz_two_spheres, punch, reverse_hertz, two_block_patch)
from signorini.scenes.registry import SCENES, get_scene, register, scene_reference, unregister

# in this order the validation suite runs their cases (the simplest scene first)
for _module in (block, hertz_cylinder, hertz_sphere, hertz_sphere_3d, punch, reverse_hertz,
                two_block_patch, hertz_two_cylinders, hertz_two_spheres):
    register(_module.FAMILY)

#: the families every process knows (registered on import of the package)
BUILT_IN = frozenset(SCENES)


def portable_scene(name: str) -> bool:
    """A worker process (:mod:`signorini.studies.runner`) can build this scene: a built-in
    family, a scene file or a problem file. A family registered in this process only is not."""
    return name in BUILT_IN or name.lower().endswith(".toml") or is_problem_file(name)


__all__ = ["BUILT_IN", "SCENES", "get_scene", "portable_scene", "register", "scene_reference",
           "unregister"]
