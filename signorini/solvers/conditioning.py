"""A method's private view of a problem in units that make its numbers of order one.

A problem holds its QP in the units it was given (:meth:`ContactProblem.from_qp`
keeps the user's arrays). A method with absolute thresholds inside (a QP backend's
``eps_abs``, a step length, a pivot tolerance) needs numbers of order one; it is handed
a view with ``K̂ = K/k``, ``f̂ = f/(kU)``, ``d̂ = d/U`` and ``ŵ = w/W``
(:func:`signorini.scales.qp_scales` chooses k, U and W), whose ``scales`` say how to go
back, and its answer is mapped back (``u = U û``, ``λ = kU λ̂``) before it is judged. The
view is made per run and never stored on the problem. A problem a model made
dimensionless already (its ``scales`` are not the identity: a scene's), or whose numbers are of
order one already (every scale within a factor :data:`ORDER_ONE` of 1), is its own view:
scaling it would change its round-off and nothing else.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from signorini.problem import ContactProblem, ContactSolution
from signorini.scales import Scales, qp_scales
from signorini.solution import WarmStart

__all__ = ["ORDER_ONE", "UnitsFactor", "in_problem_units", "scaled_view"]

#: a scale within this factor of 1 is of order one
ORDER_ONE = 10.0


def scaled_view(problem: ContactProblem, options: dict[str, Any]) -> tuple[ContactProblem, Scales]:
    """``(view, scales)``: ``problem`` in units of order one and the units that undo it; the
    options' warm start (an earlier answer in the problem's units) is moved into the view."""
    if problem.scales != Scales():
        return problem, Scales()
    s = qp_scales(problem.K, problem.f, problem.d, problem.weights)
    if all(1 / ORDER_ONE <= value <= ORDER_ONE for value in (s.displacement, s.force, s.weight)):
        return problem, Scales()
    view = dataclasses.replace(
        problem, K=problem.K * (s.displacement / s.force), f=problem.f / s.force,
        d=problem.d / s.displacement, scales=s,
        weights=None if problem.weights is None else problem.weights / s.weight)
    warm = options.get("warm_start")
    if isinstance(warm, WarmStart):
        options["warm_start"] = dataclasses.replace(
            warm, lam=None if warm.lam is None else np.asarray(warm.lam) / s.force,
            u=None if warm.u is None else np.asarray(warm.u) / s.displacement)
    return view, s


def in_problem_units(problem: ContactProblem, solution: ContactSolution,
                     scales: Scales) -> ContactSolution:
    """``solution`` of the view made with ``scales``, as an answer of ``problem`` itself."""
    if scales == Scales():
        return solution
    solution.u = solution.u * scales.displacement
    solution.lam = solution.lam * scales.force
    if solution.factor is not None:
        solution.factor = UnitsFactor(solution.factor, problem.K,
                                      scales.force / scales.displacement)
    return solution


class UnitsFactor:
    """A factorisation of the view's ``K̂ = K/k`` that solves with the problem's ``K``.

    ``solve(rhs)`` gives u with ``(K u)[free] = rhs[free]`` and ``u[fixed] = rhs[fixed]``
    (the pinned dofs of the factorisation, none for a plain one): the loads are divided
    by k, the prescribed values kept. ``matrix`` is the problem's K, so that the
    certificate reuses it; the Delassus operator a factorisation carries is ``Ŵ/k``.
    """

    def __init__(self, factor: Any, K: Any, stiffness: float):
        self.factor, self.matrix, self.stiffness = factor, K, stiffness
        self.fixed = np.asarray(getattr(factor, "fixed", np.zeros(0, dtype=int)), dtype=int)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.factor, name)

    @property
    def delassus(self) -> Any:
        W = getattr(self.factor, "delassus", None)
        return None if W is None else W / self.stiffness

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        scaled = np.array(rhs, dtype=float) / self.stiffness
        scaled[self.fixed] = np.asarray(rhs, dtype=float)[self.fixed]
        return self.factor.solve(scaled)

    def fixed_rows(self, u: np.ndarray) -> np.ndarray:
        """``(K u)[fixed]``."""
        return self.stiffness * self.factor.fixed_rows(u)
