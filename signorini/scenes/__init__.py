"""Scene families: name → parameters and a builder."""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..problem import ContactProblem
from . import block, hertz_cylinder
from .base import FlatObstacle, Param, SceneFamily, SceneModel

SCENES: dict[str, SceneFamily] = {f.name: f for f in (hertz_cylinder.FAMILY, block.FAMILY)}


def get_scene(name: str) -> SceneFamily:
    """Look a scene family up by name; unknown names list the known ones."""
    if name not in SCENES:
        raise InputError(f"unknown scene {name!r}: choose one of {', '.join(sorted(SCENES))}")
    return SCENES[name]


def build_problem(name: str, nondimensionalise: bool = True, **values: Any) -> ContactProblem:
    """Build scene ``name`` with parameter ``values`` and assemble its contact problem."""
    from ..assembly import assemble

    family = get_scene(name)
    params = family.parse(values)
    model = family.build(params, set(values))
    problem = assemble(model, nondimensionalise=nondimensionalise)
    problem.scene = name
    return problem


__all__ = ["SCENES", "FlatObstacle", "Param", "SceneFamily", "SceneModel", "build_problem", "get_scene"]
