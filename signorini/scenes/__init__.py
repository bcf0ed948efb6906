"""Scenes: families of bodies and obstacles by name, scene files, and building their problems.

A scene family is one module with a ``FAMILY = SceneFamily(...)`` that owns what is
known of it (parameters, builder, size model, coarse rule, snapping, reference,
validation cases) and one :func:`register` call.
"""

from signorini.fem.model import FlatObstacle, SceneModel
from signorini.scenes.base import Case, Param, SceneFamily
from signorini.scenes.build import build_problem, coarse_problem, coarse_values
from signorini.scenes.families import SCENES, get_scene, portable_scene, register, scene_reference, unregister

__all__ = ["SCENES", "Case", "FlatObstacle", "Param", "SceneFamily", "SceneModel", "build_problem",
           "coarse_problem", "coarse_values", "get_scene", "portable_scene", "register", "scene_reference",
           "unregister"]
