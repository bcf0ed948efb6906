"""Scene families: name → parameters and a builder."""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..problem import ContactProblem, Scales
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


#: load targeting on a model of at least this many dofs first solves a coarser model of the
#: scene (when the family has one) and calibrates around its contact zone (signorini.nested)
NESTED_FROM_DOFS = 20_000
_LOAD_NAMES = ("P", "delta", "a_over_R", "load_ratio")


def coarse_values(name: str, params: dict[str, Any]) -> dict[str, Any] | None:
    """Parameters of a model of scene ``name`` about 16 times coarser than ``params``, or None.

    Families with ``refine`` and ``n_contact`` lose two uniform refinements
    (or one, and half the elements across the contact); the load is the
    same target P, or the same push ``delta`` when no target was set.
    """
    family = SCENES.get(name)
    names = {p.name for p in family.params} if family else set()
    if not {"refine", "n_contact", "P", "delta"} <= names:
        return None
    values = {k: v for k, v in params.items() if k in names and k not in _LOAD_NAMES}
    if params["refine"] >= 2:
        values["refine"] = params["refine"] - 2
    elif params["refine"] == 1 and params["n_contact"] >= 8:
        values.update(refine=0, n_contact=params["n_contact"] // 2)
    else:
        return None
    if params.get("P") is not None:
        values["P"] = params["P"]
    elif params.get("delta") is not None:
        values["delta"] = params["delta"]
    else:
        return None
    return values


def _coarse_model(name: str, params: dict[str, Any], nondimensionalise: bool):
    """The coarser model of :func:`coarse_values`, or None (none, or parameters out of range)."""
    values = coarse_values(name, params)
    if values is None:
        return None
    try:
        return build_problem(name, nondimensionalise=nondimensionalise, **values)
    except InputError:  # the coarser parameters are out of range: no coarse model
        return None


def coarse_problem(problem: ContactProblem) -> ContactProblem | None:
    """A coarser model of the scene ``problem`` was built from (None when there is none)."""
    return _coarse_model(problem.scene, problem.params, problem.scales != Scales())


def predicted_zone(name: str, model: SceneModel, nondimensionalise: bool):
    """The contact zone of a large load-targeted model, predicted from a coarser one (or None)."""
    from ..nested import zone_from_coarse

    dofs = model.mesh.p.shape[0] * model.mesh.p.shape[1]
    if model.target_load is None or dofs < NESTED_FROM_DOFS:
        return None
    coarse = _coarse_model(name, model.params, nondimensionalise)
    if coarse is None:
        return None
    return zone_from_coarse(model.mesh.p[:, model.contact_nodes].T / coarse.scales.length, coarse)


def build_problem(name: str, nondimensionalise: bool = True, **values: Any) -> ContactProblem:
    """Build scene ``name`` with parameter ``values`` and assemble its contact problem.

    ``name`` may be the path of a TOML scene file (``*.toml``, see
    :mod:`signorini.scenefile`); ``values`` then override its parameters.
    """
    from ..assembly import assemble

    zone = None
    if name.lower().endswith(".toml"):  # a scene file: signorini.scenefile
        from ..scenefile import build_scene_model

        name, model = build_scene_model(name, values)
    else:
        family = get_scene(name)
        params = family.parse(values)
        model = family.build(params, set(values))
        zone = predicted_zone(name, model, nondimensionalise)
    problem = assemble(model, nondimensionalise=nondimensionalise, zone=zone)
    problem.scene = name
    return problem


__all__ = ["SCENES", "FlatObstacle", "Param", "SceneFamily", "SceneModel", "build_problem",
           "coarse_problem", "coarse_values", "get_scene", "scene_reference"]
