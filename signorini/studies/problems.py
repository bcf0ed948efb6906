"""The problems a study runs on, as JSON-able specs, and the trusted answers it compares with.

A worker process rebuilds a problem from its spec (:func:`build_spec`), so
a study can send runs to a fresh process; a reference policy
(:func:`reference_solution`) says which exact answer a run is held to.
"""

from __future__ import annotations

import logging
from typing import Any

import numpy as np

from signorini.diagnose import regularise
from signorini.errors import InputError
from signorini.fem.assembly import assemble
from signorini.fem.model import FlatObstacle
from signorini.problem import ContactProblem, ContactSolution
from signorini.scenes import block, build_problem
from signorini.scenes.block import force_controlled_exact, force_controlled_problem
from signorini.solvers.registry import solve

log = logging.getLogger(__name__)

#: tolerance of the trusted exact answer (PDAS)
REFERENCE_TOL = 1e-9


def build_spec(spec: dict[str, Any]) -> ContactProblem:
    """The problem a spec describes (a JSON-able dict, so that a worker can rebuild it).

    ``{"kind": "scene", "scene", "params", "nondimensionalise"}``,
    ``{"kind": "force-controlled", "params", "pressure", "regularisation"}`` or
    ``{"kind": "ill-posed", "case", "params"}`` (see :func:`ill_posed_problem`).
    """
    kind = spec["kind"]
    if kind == "scene":
        return build_problem(spec["scene"], nondimensionalise=spec.get("nondimensionalise", True),
                             **spec.get("params", {}))
    if kind == "force-controlled":
        problem = force_controlled_problem(spec.get("pressure", 0.01), **spec.get("params", {}))
        epsilon = spec.get("regularisation", 0.0)
        return regularise(problem, epsilon) if epsilon else problem
    if kind == "ill-posed":
        return ill_posed_problem(spec["case"], **spec.get("params", {}))
    raise ValueError(f"unknown problem kind {kind!r}")


#: the ill-posed and infeasible inputs of axis 8
ILL_POSED_CASES = {
    "penetrated": "the Dirichlet data push the bottom 0.5 δ through the flat (bottom prescribed)",
    "no-candidates": "an empty contact set (no candidate node)",
    "zero-weight": "a candidate that lies on no contact edge (weight 0)",
    "duplicate": "one bottom node listed twice as a candidate (λ not unique)",
    "never-touches": "the flat 0.1 H below the bottom: contact never closes (λ = 0)",
}


def ill_posed_problem(case: str, **values: Any) -> ContactProblem:
    """The block (``values`` are its parameters) made infeasible or ill-posed as ``case`` says.

    ``case`` is one of :data:`ILL_POSED_CASES`. Cases the package refuses
    raise :class:`~signorini.errors.InputError` here, from the assembly.
    """
    if case not in ILL_POSED_CASES:
        raise InputError(f"unknown ill-posed case {case!r}: choose {', '.join(ILL_POSED_CASES)}")
    p = block.FAMILY.parse(values)
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
    problem.scene = f"block ({case})"
    return problem


def reference_solution(problem: ContactProblem, spec: dict[str, Any],
                       other: ContactProblem | None = None) -> ContactSolution | None:
    """The trusted exact answer for ``problem`` in its own units, or None when there is none.

    ``spec["kind"]``: ``"pdas"`` (PDAS at :data:`REFERENCE_TOL` on ``problem``,
    or on ``other`` — the same mesh in other units — converted), or
    ``"force-controlled-exact"`` (the patch solution).
    """
    if spec["kind"] == "force-controlled-exact":
        return force_controlled_exact(problem)
    source = problem if other is None else other
    try:
        solution = solve(source, "pdas", tol=REFERENCE_TOL)
    except Exception as exc:  # the reference is optional: say so and go on
        log.warning("no reference for %s: pdas raised %s", problem.scene, exc)
        return None
    if solution.status != "converged":
        return None
    if other is not None and spec.get("displacement_only"):
        if other.n != problem.n:
            raise ValueError("the reference problem has another mesh")
        u_ratio = other.scales.displacement / problem.scales.displacement
        return ContactSolution(method="pdas", u=solution.u * u_ratio,
                               lam=np.full(problem.m, np.nan), status="converged",
                               message=f"pdas displacement of another problem ({solution.message})")
    if other is not None:
        if other.n != problem.n or other.m != problem.m:
            raise ValueError("the reference problem has another mesh")
        u_ratio = other.scales.displacement / problem.scales.displacement
        force_ratio = other.scales.force / problem.scales.force
        solution = ContactSolution(method="pdas", u=solution.u * u_ratio,
                                   lam=solution.lam * force_ratio, status="converged",
                                   message=f"pdas in other units ({solution.message})")
    return solution
