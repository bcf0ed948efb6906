"""Scene (a family and its parameters, or a TOML file) → assembled :class:`ContactProblem`.

Large load-targeted models of families with a coarser level are assembled
around a contact zone that a model about 16 times coarser predicts
(:func:`signorini.solvers.nested.zone_from_coarse`); every problem built here
carries :func:`coarse_problem` as its coarse-model factory for the ``nested``
method.
"""

from __future__ import annotations

from typing import Any

from signorini.errors import InputError
from signorini.fem.assembly import assemble
from signorini.fem.model import SceneModel
from signorini.numerics.arrays import flag_argument
from signorini.numerics.zone import zone_around_points
from signorini.problem import ContactProblem, Scales
from signorini.references import REFERENCES
from signorini.scenes.families import SCENES, get_scene
from signorini.scenes.scenefile import build_scene_model
from signorini.scenes.size import check_size
from signorini.solvers.auto import defers_load_targeting
from signorini.solvers.nested import zone_from_coarse

#: load targeting on a model of at least this many dofs first solves a coarser model of the
#: scene (when the family has one) and calibrates around its contact zone (signorini.numerics.zone)
NESTED_FROM_DOFS = 20_000
_LOAD_NAMES = ("P", "delta", "a_over_R", "load_ratio")


def coarse_values(name: str, params: dict[str, Any]) -> dict[str, Any] | None:
    """Parameters of a model of scene ``name`` about 16 times coarser than ``params``, or None.

    Families with ``refine`` and ``n_contact`` lose two uniform refinements
    (or one, and half the elements across the contact); the load is the
    same target P, or the same push ``delta`` when no target was set; meshed
    by bisection where the family offers a choice (it only predicts the zone).
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
    if "mesher" in names:  # a zone predictor needs no well-shaped triangles: relaxing a disc of
        values["mesher"] = "bisection"  # n_contact = 110 takes 3–4 s, bisection 0.6 s (measured)
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
    """The contact zone of a large load-targeted model (or None): from the reference's analytic
    contact half-width (radius) where it has one, else from a coarser model."""
    dofs = model.mesh.p.shape[0] * model.mesh.p.shape[1]
    if model.target_load is None or dofs < NESTED_FROM_DOFS:
        return None
    reference = REFERENCES.get(SCENES[name].reference) if name in SCENES else None
    if reference is not None and reference.extent is not None:
        a = reference.extent(model.params)
        zone = None if a is None else zone_around_points(model.mesh.p[:, model.contact_nodes].T, a,
                                                         reference.extent_margin)
        if zone is not None:
            return zone
    coarse = _coarse_model(name, model.params, nondimensionalise)
    if coarse is None:
        return None
    return zone_from_coarse(model.mesh.p[:, model.contact_nodes].T / coarse.scales.length, coarse)


def build_problem(name: str, nondimensionalise: bool = True, *, solved_by: str | None = None,
                  **values: Any) -> ContactProblem:
    """Build scene ``name`` with parameter ``values`` and assemble its contact problem.

    ``name`` may be the path of a TOML scene file (``*.toml``, see
    :mod:`signorini.scenes.scenefile`); ``values`` then override its parameters.
    ``solved_by`` names the method that will solve it: when that method
    matches a target load itself (``pdas-amg``, or ``auto`` picking it for a
    large 3D model), the load targeting is left to it
    (:func:`signorini.solvers.auto.defers_load_targeting`: no factorisation of
    K in the assembly) and the problem's target is ``pending``.
    """
    nondimensionalise = flag_argument(nondimensionalise, "nondimensionalise")
    if not isinstance(name, str):
        raise InputError(f"scene must be a name or the path of a .toml scene file (a string), got "
                         f"{type(name).__name__}: e.g. build_problem('hertz-cylinder')")
    zone = None
    if name.lower().endswith(".toml"):  # a scene file: signorini.scenes.scenefile
        name, model = build_scene_model(name, values)
    else:
        family = get_scene(name)
        params = family.parse(values)
        check_size(name, params, solved_by)  # too big for this machine: refused before meshing
        try:
            model = family.build(params, set(values))
        except InputError:  # the model's own checks (signorini.fem.checks): said as they are
            raise
        except (RuntimeError, ValueError, ArithmeticError, IndexError, MemoryError) as exc:
            # the mesher gave up (too many elements, a relaxation that folded the mesh) or ran
            # out of memory: the parameters asked for a mesh it cannot make
            given = ", ".join(f"{k}={v}" for k, v in values.items()) or "its defaults"
            raise InputError(f"scene {name!r} with {given} could not be meshed "
                             f"({type(exc).__name__}: {exc}): make the mesh coarser (a larger "
                             "grading or a smaller n_contact)") from None
        zone = predicted_zone(name, model, nondimensionalise)
    defer = None if solved_by is None else (lambda p: defers_load_targeting(p, solved_by))
    problem = assemble(model, nondimensionalise=nondimensionalise, zone=zone, defer=defer)
    problem.scene = name
    problem.reference = SCENES[name].reference if name in SCENES else ""
    problem.coarse_model = coarse_problem
    return problem
