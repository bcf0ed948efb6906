"""The problems a study runs on, as JSON-able specs, and the trusted answers it compares with.

A worker process rebuilds a problem from its spec (:func:`build_spec`), so
a study can send runs to a fresh process. A reference policy, named by the
study in a spec ``{"kind": name, ...}`` (:data:`REFERENCE_POLICIES`), says
which exact answer a run is held to:

========================= ==========================================================
policy                    the exact answer
========================= ==========================================================
``pdas``                  PDAS at ``tol`` (:data:`REFERENCE_TOL`), converged
``nested``                the nested method at ``tol``, converged
``force-controlled-exact`` the patch solution of the force-controlled block
``refined``               PDAS's answer, refined in long double on its active set
``none``                  none: a run is judged by its certificate alone
========================= ==========================================================

A method's policy may solve ``problem`` (another problem in other units,
converted: the atlas's units axis) and keep its answer in a ``.npz`` file
(``"keep"``) that later runs, in other processes, read instead of solving.
"""

from __future__ import annotations

import io
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from signorini.certification.diagnosis import regularise
from signorini.errors import InputError
from signorini.fem.assembly import assemble
from signorini.fem.model import FlatObstacle
from signorini.files import atomic_write_bytes
from signorini.certification.comparison import refined_on_active_set
from signorini.certification.kkt import active_set
from signorini.load_control import at_load
from signorini.numerics.factor import factorize
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.problem.files import read_problem
from signorini.scenes import block, build_problem, coarse_problem
from signorini.scenes.base import scene_params
from signorini.scenes.block import force_controlled_exact, force_controlled_problem
from signorini.solvers.registry import solve

log = logging.getLogger(__name__)

#: tolerance of the trusted exact answer (PDAS)
REFERENCE_TOL = 1e-9
#: long-double refinement steps of the ``refined`` policy
REFINEMENT_STEPS = 20


# --- problem specs ------------------------------------------------------------------------------


def _scene(spec: dict[str, Any]) -> ContactProblem:
    # a study runs every method, cold, on the QP at the scene's load (matched once); with
    # "matched": false the scene as built, its target load left to each method (as signorini.solve)
    problem = build_problem(spec["scene"], params=spec.get("params"),
                            nondimensionalise=spec.get("nondimensionalise", True))
    return at_load(problem, coarse_problem) if spec.get("matched", True) else problem


def _force_controlled(spec: dict[str, Any]) -> ContactProblem:
    problem = force_controlled_problem(spec.get("pressure", 0.01), params=spec.get("params", {}))
    epsilon = spec.get("regularisation", 0.0)
    return regularise(problem, epsilon) if epsilon else problem


#: the kinds of problem spec and how each is built
PROBLEM_KINDS: dict[str, Callable[[dict[str, Any]], ContactProblem]] = {
    "scene": _scene, "force-controlled": _force_controlled,
    "ill-posed": lambda spec: ill_posed_problem(spec["case"], params=spec.get("params", {})),
    "stored": lambda spec: (at_load(read_problem(spec["path"]), coarse_problem)
                            if spec.get("matched", True) else read_problem(spec["path"])),
}


def build_spec(spec: dict[str, Any]) -> ContactProblem:
    """The problem a spec describes (a JSON-able dict, so that a worker can rebuild it).

    ``{"kind": "scene", "scene", "params", "nondimensionalise", "matched"}``,
    ``{"kind": "force-controlled", "params", "pressure", "regularisation"}``,
    ``{"kind": "ill-posed", "case", "params"}`` (see :func:`ill_posed_problem`) or
    ``{"kind": "stored", "path", "matched"}`` (a problem file: :meth:`ContactProblem.save`'s,
    plain ``.npz`` or Matrix Market, :mod:`signorini.problem.files`). A scene's or a stored
    problem's target load is matched once here unless ``"matched"`` is false (then each method
    solves it as :func:`signorini.solve` does).
    """
    kind = spec["kind"]
    if kind not in PROBLEM_KINDS:
        raise ValueError(f"unknown problem kind {kind!r}: one of {', '.join(PROBLEM_KINDS)}")
    return PROBLEM_KINDS[kind](spec)


def candidate_spacing(problem: ContactProblem) -> float:
    """Median distance from each contact candidate to its nearest neighbour (physical units)."""
    from scipy.spatial import cKDTree  # on use: scipy.spatial is slow to import

    points = problem.contact_points * problem.scales.length
    if len(points) < 2 or not np.all(np.isfinite(points)):  # no positions: a QP given as arrays
        return float("nan")
    distance, _ = cKDTree(points).query(points, k=2)
    return float(np.median(distance[:, 1]))


#: the ill-posed and infeasible inputs of axis 8
ILL_POSED_CASES = {
    "penetrated": "the Dirichlet data push the bottom 0.5 δ through the flat (bottom prescribed)",
    "no-candidates": "an empty contact set (no candidate node)",
    "zero-weight": "a candidate that lies on no contact edge (weight 0)",
    "duplicate": "one bottom node listed twice as a candidate (λ not unique)",
    "never-touches": "the flat 0.1 H below the bottom: contact never closes (λ = 0)",
}


def ill_posed_problem(case: str, params: dict[str, Any] | None = None) -> ContactProblem:
    """The block (``params`` are its parameters) made infeasible or ill-posed as ``case`` says.

    ``case`` is one of :data:`ILL_POSED_CASES`. Cases the package refuses
    raise :class:`~signorini.errors.InputError` here, from the assembly.
    """
    if case not in ILL_POSED_CASES:
        raise InputError(f"unknown ill-posed case {case!r}: choose {', '.join(ILL_POSED_CASES)}")
    p = block.FAMILY.parse(scene_params(params))
    model = block.build(p)
    bottom = model.contact_nodes
    if case == "penetrated":
        model.dirichlet.append((1, bottom, -0.5 * p["delta"]))
    elif case == "no-candidates":
        model.contact_nodes = bottom[:0]
    elif case == "zero-weight":
        x, y = model.mesh.p
        interior = int(np.argmin(np.hypot(x - 0.5 * p["W"], y - 0.5 * p["H"])))
        model.contact_nodes = np.append(bottom, interior)
    elif case == "duplicate":
        model.contact_nodes = np.append(bottom, bottom[len(bottom) // 2])
    elif case == "never-touches":
        model.obstacle = FlatObstacle(-0.1 * p["H"])
    problem = assemble(model)
    problem.name = f"block ({case})"
    return problem


# --- reference policies -------------------------------------------------------------------------


@dataclass(frozen=True)
class ReferencePolicy:
    """A way to the trusted exact answer of a problem.

    ``attempt(problem, spec, other)`` returns the policy's answer, converged
    or not (None when the policy has none); only a converged answer is
    trusted (:func:`trusted`). ``method`` names the method whose answer it
    is, so that a run of that very method (same tolerance, no options) can
    serve as its own reference instead of being solved twice.
    """

    name: str
    summary: str
    attempt: Callable[[ContactProblem, dict[str, Any], ContactProblem | None],
                      ContactSolution | None]
    method: str | None = None


def _converted(problem: ContactProblem, other: ContactProblem, solution: ContactSolution,
               displacement_only: bool) -> ContactSolution:
    """``other``'s answer in ``problem``'s units (the same mesh); λ left out if asked."""
    if other.n != problem.n or (not displacement_only and other.m != problem.m):
        raise ValueError("the reference problem has another mesh")
    u_ratio = other.scales.displacement / problem.scales.displacement
    if displacement_only:
        return ContactSolution(method=solution.method, u=solution.u * u_ratio,
                               lam=np.full(problem.m, np.nan), status="converged",
                               message=f"{solution.method} displacement of another problem "
                                       f"({solution.message})")
    force_ratio = other.scales.force / problem.scales.force
    return ContactSolution(method=solution.method, u=solution.u * u_ratio,
                           lam=solution.lam * force_ratio, status="converged",
                           message=f"{solution.method} in other units ({solution.message})")


def _solved_by(method: str) -> Callable[..., ContactSolution]:
    """A policy's attempt: ``method`` at ``spec["tol"]`` on the problem (or on ``other``, converted)."""

    def attempt(problem: ContactProblem, spec: dict[str, Any],
                other: ContactProblem | None) -> ContactSolution:
        source = problem if other is None else other
        try:
            solution = solve(source, method, tol=spec.get("tol", REFERENCE_TOL))
        except Exception as exc:  # the reference is optional: say so and go on
            log.warning("no reference for %s: %s raised %s", problem.name, method, exc)
            return ContactSolution.failure(method, problem, "failed", f"{type(exc).__name__}: {exc}")
        if other is None or solution.status != "converged":
            return solution
        return _converted(problem, other, solution, bool(spec.get("displacement_only")))

    return attempt


def _refined(problem: ContactProblem, spec: dict[str, Any],
             other: ContactProblem | None) -> ContactSolution:
    """PDAS's answer with (u, λ) refined in long double on its active set (``spec["steps"]``).

    Its active set is taken whatever the certificate said of its λ (near ν = ½ it cannot
    certify λ, which is what the refinement is for); an answer with no finite λ is returned as is.
    """
    start = _solved_by("pdas")(problem, spec, other)
    if not (np.all(np.isfinite(start.u)) and np.all(np.isfinite(start.lam))):
        return start
    u, lam = refined_on_active_set(problem.K, problem.f, problem.N, problem.d, start.u, start.lam,
                                   active_set(problem, start), factorize(problem.K),
                                   steps=spec.get("steps", REFINEMENT_STEPS))
    return ContactSolution("pdas", u.astype(float), lam.astype(float), "converged",
                           message=f"pdas refined in long double ({start.message})")


REFERENCE_POLICIES: dict[str, ReferencePolicy] = {p.name: p for p in (
    ReferencePolicy("pdas", "PDAS (exact when it converges) at tol, REFERENCE_TOL unless given",
                    _solved_by("pdas"), method="pdas"),
    ReferencePolicy("nested", "the nested method (exact when it converges) at tol",
                    _solved_by("nested"), method="nested"),
    ReferencePolicy("force-controlled-exact", "the patch solution of the force-controlled block",
                    lambda problem, spec, other: force_controlled_exact(problem)),
    ReferencePolicy("refined", "PDAS's answer refined in long double on its active set "
                    "(steps: REFINEMENT_STEPS unless given)", _refined),
    ReferencePolicy("none", "no exact answer: a run is judged by its certificate alone",
                    lambda problem, spec, other: None),
)}


def reference_policy(spec: dict[str, Any]) -> ReferencePolicy:
    """The policy a reference spec names; unknown names list the known ones."""
    name = spec.get("kind")
    if name not in REFERENCE_POLICIES:
        raise ValueError(f"unknown reference policy {name!r}: one of {', '.join(REFERENCE_POLICIES)}")
    return REFERENCE_POLICIES[name]


def exact_attempt(problem: ContactProblem, spec: dict[str, Any], other: ContactProblem | None = None,
                  own: ContactSolution | None = None) -> ContactSolution | None:
    """The policy's answer for ``problem``, converged or not (None when it has none).

    ``own`` is the run's answer when the run is the policy's own (see
    :attr:`ReferencePolicy.method`): it is taken instead of solving again.
    With ``spec["keep"]`` (a ``.npz`` path) a converged answer is stored
    there, and read from there by later calls.
    """
    policy = reference_policy(spec)
    keep = spec.get("keep")
    if keep and Path(keep).exists():
        stored = np.load(keep)
        return ContactSolution(policy.method or policy.name, stored["u"], stored["lam"], "converged",
                               message=f"read from {keep}")
    answer = own if own is not None else policy.attempt(problem, spec, other)
    if keep and answer is not None and answer.status == "converged":
        buffer = io.BytesIO()
        np.savez(buffer, u=answer.u, lam=answer.lam)
        atomic_write_bytes(keep, buffer.getvalue())
    return answer


def trusted(answer: ContactSolution | None) -> ContactSolution | None:
    """``answer`` when it converged, else None (nothing to hold a run to)."""
    return answer if answer is not None and answer.status == "converged" else None


__all__ = ["build_spec", "candidate_spacing", "ill_posed_problem", "ReferencePolicy",
           "reference_policy", "exact_attempt", "trusted", "REFERENCE_TOL", "PROBLEM_KINDS",
           "ILL_POSED_CASES", "REFERENCE_POLICIES"]
