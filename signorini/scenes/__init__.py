"""Scene families: name → parameters and a builder."""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..problem import ContactProblem
from . import block, hertz_cylinder, hertz_sphere, hertz_sphere_3d, punch, reverse_hertz
from .base import FlatObstacle, Param, SceneFamily, SceneModel

SCENES: dict[str, SceneFamily] = {f.name: f for f in (hertz_cylinder.FAMILY, block.FAMILY,
                                                     hertz_sphere.FAMILY, hertz_sphere_3d.FAMILY,
                                                     punch.FAMILY, reverse_hertz.FAMILY)}


def get_scene(name: str) -> SceneFamily:
    """Look a scene family up by name; unknown names list the known ones."""
    if name not in SCENES:
        raise InputError(f"unknown scene {name!r}: choose one of {', '.join(sorted(SCENES))} "
                         "(or give the path of a .toml scene file)")
    return SCENES[name]


def scene_reference(name: str) -> str:
    """The analytic reference of scene ``name`` ("" for scenes read from mesh files)."""
    return SCENES[name].reference if name in SCENES else ""


def build_problem(name: str, nondimensionalise: bool = True, **values: Any) -> ContactProblem:
    """Build scene ``name`` with parameter ``values`` and assemble its contact problem.

    ``name`` may be the path of a TOML scene file (``*.toml``, see
    :mod:`signorini.scenefile`); ``values`` then override its parameters.
    """
    from ..assembly import assemble

    if name.lower().endswith(".toml"):  # a scene file: signorini.scenefile
        from ..scenefile import build_scene_model

        name, model = build_scene_model(name, values)
    else:
        family = get_scene(name)
        params = family.parse(values)
        model = family.build(params, set(values))
    problem = assemble(model, nondimensionalise=nondimensionalise)
    problem.scene = name
    return problem


__all__ = ["SCENES", "FlatObstacle", "Param", "SceneFamily", "SceneModel", "build_problem", "get_scene",
           "scene_reference"]
