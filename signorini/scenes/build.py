"""Scene (a family and its parameters, or a TOML file) → assembled :class:`ContactProblem`.

Building solves nothing: a scene with a target load gives a problem whose
target is pending, matched by load control (:mod:`signorini.load_control`).
:func:`coarse_problem` builds a model of the same scene about 16 times
coarser, which predicts the contact zone of large models.
"""

from __future__ import annotations

import logging
import time
from typing import Any

from signorini.errors import InputError
from signorini.fem.assembly import assemble
from signorini.fem.two_bodies import TwoBodyModel
from signorini.numerics.arrays import flag_argument
from signorini.numerics.zone import radial_distance
from signorini.problem.contact import ContactProblem, Scales
from signorini.problem.files import is_problem_file, read_problem
from signorini.references.catalogue import reference_of
from signorini.scenes.base import GRADING_RANGE, LOAD_NAMES, scene_params
from signorini.scenes.families import SCENES, get_scene, scene_reference
from signorini.scenes.scenefile import build_scene_model
from signorini.scenes.size import Solver, check_size

log = logging.getLogger(__name__)


def coarse_values(name: str, params: dict[str, Any]) -> dict[str, Any] | None:
    """Parameters of a model of scene ``name`` about 16 times coarser than ``params``, or None.

    The family's own rule (:attr:`~signorini.scenes.base.SceneFamily.coarse`, e.g.
    :func:`~signorini.scenes.base.two_refinements_coarser`) on the family's
    parameters; None for a family without one (or a scene file).
    """
    family = SCENES.get(name)
    if family is None or family.coarse is None:
        return None
    names = {p.name for p in family.params}
    return family.coarse({k: v for k, v in params.items() if k in names})


def coarse_problem(problem: ContactProblem) -> ContactProblem | None:
    """The model of :func:`coarse_values` of the scene ``problem`` was built from (None when there
    is none, or when its parameters are out of range)."""
    values = coarse_values(problem.name, problem.model.params)
    if values is None:
        return None
    try:
        return build_problem(problem.name, params=values, nondimensionalise=problem.scales != Scales())
    except InputError:  # the coarser parameters are out of range: no coarse model
        return None


def build_problem(name: str, params: dict[str, Any] | None = None, *, nondimensionalise: bool = True,
                  solved_by: Solver | None = None) -> ContactProblem:
    """Build scene ``name`` with parameters ``params`` and assemble its contact problem.

    ``params`` maps the scene's parameter names to values in its units (see
    :func:`signorini.scene_families`; None: the defaults). ``name`` may be the
    path of a TOML scene file (``*.toml``, see :mod:`signorini.scenes.scenefile`);
    ``params`` then override its parameters. ``name`` may also be a problem
    file (``.npz`` or Matrix Market, :mod:`signorini.problem.files`): its QP is
    read as stored, with no parameters to set. A target load stays pending (load
    control matches it when the problem is solved). ``solved_by`` is the
    method that will solve it, for the size guard (a method that never
    factorises needs less memory). The problem's ``model.mesh_s`` is
    the time spent up to assembly (checking, meshing, the model) and
    ``assemble_s`` assembly's.
    """
    start = time.perf_counter()
    values = scene_params(params)
    nondimensionalise = flag_argument(nondimensionalise, "nondimensionalise")
    if not isinstance(name, str):
        raise InputError(f"scene must be a name or the path of a .toml scene file (a string), got "
                         f"{type(name).__name__}: e.g. build_problem('hertz-cylinder')")
    if name not in SCENES and is_problem_file(name):  # a problem file: read, not built
        if values:
            raise InputError(f"problem file {name!r} has no scene parameters to set "
                             f"({', '.join(values)}): drop params (--set)")
        if not nondimensionalise:
            raise InputError(f"problem file {name!r} is solved in the units it was written in: "
                             "drop nondimensionalise=False (--raw-units)")
        problem = read_problem(name)  # reading it is what building it costs
        problem.model = problem.model.with_basis(mesh_s=time.perf_counter() - start, assemble_s=0.0)
        return problem
    if name.lower().endswith(".toml"):  # a scene file: signorini.scenes.scenefile
        log.info("meshing %s", name)
        name, model = build_scene_model(name, values)
    else:
        family = get_scene(name)
        parsed = family.parse(values)
        check_size(name, parsed, solved_by)  # too big for this machine: refused before meshing
        log.info("meshing %s", name)
        try:
            model = family.build(parsed, set(values))
        except InputError:  # the model's own checks (signorini.fem.checks): said as they are
            raise
        except (RuntimeError, ValueError, ArithmeticError, IndexError, MemoryError) as exc:
            # the mesher gave up (too many elements, a relaxation that folded the mesh) or ran
            # out of memory: the parameters asked for a mesh it cannot make
            given = ", ".join(f"{k}={v}" for k, v in values.items()) or "its defaults"
            relaxed = parsed.get("mesher") == "relaxed" and "grading" in parsed
            lo, hi = GRADING_RANGE
            default = next((q.default for q in family.params if q.name == "grading"), None)
            raise InputError(
                f"scene {name!r} with {given} could not be meshed" + (
                    f" by the relaxed mesher, which folds nearly uniform meshes: give a larger "
                    f"grading (in [{lo:g}, {hi:g}], default {default}), a smaller n_contact, or "
                    "mesher=bisection" if relaxed else
                    f" ({type(exc).__name__}: {exc}): make the mesh coarser (a larger grading or "
                    "a smaller n_contact)")) from None
    declared = scene_reference(name)
    if model.reference is None and declared or model.reference and model.reference.name != declared:
        raise InputError(f"scene family {name!r} declares the reference {declared!r}, but its build "
                         f"hands on {model.reference!r}: give its SceneModel "
                         f"reference=ReferenceData({declared!r}, ...) with the fields that "
                         "reference reads (signorini.problem.contact.ReferenceData)")
    mesh_s = time.perf_counter() - start
    problem = (model.assemble(nondimensionalise) if isinstance(model, TwoBodyModel)
               else assemble(model, nondimensionalise=nondimensionalise))
    problem.name = name
    problem.model.mesh_s = mesh_s
    return problem


def with_load(problem: ContactProblem, **load: float) -> ContactProblem:
    """``problem``, built from a scene by name, at another target load on the same mesh and K.

    ``load`` names the scene's load parameters in its units, as
    :func:`build_problem` takes them: ``with_load(problem, P=2.5)`` or
    ``with_load(problem, a_over_R=0.08)``. Nothing is meshed or assembled, and K's
    factorisation, when cached, is kept (:meth:`ContactProblem.with_target`): what a
    load slider needs. The mesh stays graded for the load it was built at, so
    the answer is that mesh's; a contact zone that outgrows the candidates is
    judged ``model_inadequate`` as in any solve.
    """
    if not isinstance(problem, ContactProblem):
        raise InputError(f"with_load takes a ContactProblem, got {type(problem).__name__}: build "
                         "one first, problem = signorini.build_problem('hertz-cylinder')")
    family = SCENES.get(problem.name or "")
    if family is None or family.loads is None or problem.model.push is None or problem.model.push.target is None:
        raise InputError("with_load moves the target load of a scene built by name with one "
                         "(P or a_over_R): build this problem again with the new load instead")
    moved = sorted(set(load) - set(LOAD_NAMES))
    unset = [name for name, value in load.items() if value is None and name not in moved]
    if unset:
        raise InputError(f"with_load: {unset[0]}=None moves no load: give it a number, e.g. "
                         f"with_load(problem, {unset[0]}=...)")
    if not load or moved:
        raise InputError(f"with_load takes the scene's load ({', '.join(LOAD_NAMES)}), got "
                         f"{', '.join(moved) or 'none'}: e.g. with_load(problem, P=2.5)")
    kept = {p.name: problem.model.params[p.name] for p in family.params
            if p.name in problem.model.params and p.name not in LOAD_NAMES}
    target = family.loads(family.parse({**kept, **load}), set(load))[0]
    if target is None:
        raise InputError("with_load moves a target load: give P (or a_over_R); a prescribed push "
                         "delta is a new build")
    recorded = {**problem.model.params, **{name: None for name in LOAD_NAMES if name in problem.model.params},
                **load, "P": target}
    moved = problem.with_target(target, recorded)
    reference = reference_of(moved)  # load control starts from the reference's contact zone
    a = reference.extent(moved) if reference is not None and reference.extent else None
    if a is None:
        return moved
    return problem.with_target(target, recorded, radial_distance(moved.contact_points)
                               < a / moved.scales.length)


__all__ = ["coarse_values", "coarse_problem", "build_problem", "with_load"]
