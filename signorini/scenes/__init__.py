"""Scenes: families of bodies and obstacles by name, scene files, and building their problems."""

from signorini.fem.model import FlatObstacle, SceneModel
from signorini.scenes.base import Param, SceneFamily
from signorini.scenes.build import build_problem, coarse_problem, coarse_values
from signorini.scenes.families import SCENES, get_scene, scene_reference

__all__ = ["SCENES", "FlatObstacle", "Param", "SceneFamily", "SceneModel", "build_problem",
           "coarse_problem", "coarse_values", "get_scene", "scene_reference"]
