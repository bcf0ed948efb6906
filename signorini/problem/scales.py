"""The units that make a contact problem dimensionless (:class:`Scales`), how they are chosen
for a QP given as arrays (:func:`qp_scales`), and a method's private view of a problem in them.

A problem holds its QP in the units it was given (:meth:`ContactProblem.from_qp`
keeps the user's arrays). A method with absolute thresholds inside (a QP backend's
``eps_abs``, a step length, a pivot tolerance) needs numbers of order one; the registry
hands it a view (:func:`scaled_view`) with ``K̂ = K/k``, ``f̂ = f/(kU)``, ``d̂ = d/U`` and
``ŵ = w/W`` (:func:`qp_scales` chooses k, U and W), whose ``scales`` say how to go back,
and maps its answer back (``u = U û``, ``λ = kU λ̂``, :func:`in_problem_units`) before it is
judged. The view is made per run and never stored on the problem. A problem a model made
dimensionless already (its ``scales`` are not the identity: a scene's), or whose numbers are
of order one already (every scale within a factor :data:`ORDER_ONE` of 1), is its own view:
scaling it would change its round-off and nothing else.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from signorini.problem.solution import WarmStart

__all__ = ["ORDER_ONE", "Scales", "UnitsFactor", "in_problem_units", "qp_scales", "record_units",
           "scaled_view"]


@dataclass(frozen=True)
class Scales:
    """Units that make the problem dimensionless.

    A physical quantity is its dimensionless value times its scale:
    coordinates ``x = length · x̂``, displacements and gaps
    ``u = displacement · û``, contact forces ``λ = force · λ̂``, weights
    ``w = weight · ŵ`` and pressures ``p = λ / w = pressure · p̂`` with
    ``pressure = force / weight``. In 2D (per unit thickness)
    ``force = E · displacement`` and ``weight = length``; in 3D and in
    axisymmetric models ``force = E · displacement · length`` and
    ``weight = length²``. Axisymmetric forces and weights (``∫ φᵢ r ds``) are
    **per radian**; ``force_multiplicity`` (2π times any other copies) turns
    ``Σλ`` into the force on the whole body. Scaling the
    displacement apart from the geometry matters: a Hertz contact at
    a/R = 0.05 moves by about 1e-3 R, and a solver's absolute tolerances
    only mean something when the unknowns are of order one.
    """

    length: float = 1.0
    displacement: float = 1.0
    force: float = 1.0
    weight: float = 1.0

    @property
    def pressure(self) -> float:
        return self.force / self.weight


def qp_scales(K: sp.spmatrix, f: np.ndarray, d: np.ndarray,
              weights: np.ndarray | None = None) -> Scales:
    """The units that make a QP given as arrays dimensionless, by a scene's rule.

    A scene divides K by its stiffness ``E·L^k`` and displacements by its
    largest prescribed displacement, else its largest gap. A QP given as arrays
    has its prescribed displacements lifted into f and d, so: the stiffness
    ``k`` is the mean of K's diagonal, the displacement ``U`` the larger of
    ``‖d‖∞`` and ``‖f‖∞ / k`` (the gaps, and how far the load moves one dof),
    the force ``k·U`` (so that ``K̂ = K/k``, ``f̂ = f/(k·U)``, ``d̂ = d/U`` and
    ``λ̂ = λ/(k·U)``) and the weight the mean weight. A scale that comes out
    zero is 1; lengths keep the user's unit.
    """
    diagonal = np.abs(K.diagonal())
    stiffness = float(np.mean(diagonal)) if diagonal.size else 0.0
    stiffness = stiffness if np.isfinite(stiffness) and stiffness > 0 else 1.0
    largest = max(float(np.max(np.abs(d), initial=0.0)),
                  float(np.max(np.abs(f), initial=0.0)) / stiffness)
    displacement = largest if np.isfinite(largest) and largest > 0 else 1.0
    weight = float(np.mean(weights)) if weights is not None and weights.size else 1.0
    return Scales(length=1.0, displacement=displacement, force=stiffness * displacement,
                  weight=weight)


#: a scale within this factor of 1 is of order one
ORDER_ONE = 10.0


def scaled_view(problem: Any, options: dict[str, Any]) -> tuple[Any, Scales]:
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


def in_problem_units(problem: Any, solution: Any, scales: Scales) -> Any:
    """``solution`` of the view made with ``scales``, as an answer of ``problem`` itself."""
    if scales == Scales():
        return solution
    solution.u = solution.u * scales.displacement
    solution.lam = solution.lam * scales.force
    stiffness = scales.force / scales.displacement
    in_units = getattr(solution.factor, "in_units", None)  # a saddle-point system's own
    if solution.factor is not None:
        solution.factor = (in_units(problem.K, stiffness) if in_units is not None
                           else UnitsFactor(solution.factor, problem.K, stiffness))
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


def record_units(problem: Any) -> dict[str, str]:
    """The unit of each physical quantity of the solve record, in the problem's input units.

    A scene's units are those of its parameters: ``length`` the unit its lengths are given in
    (R, W, H, mesh coordinates), ``stress`` the unit of E; so a scene given in SI has lengths
    in m and pressures in Pa. A problem from its QP data (:meth:`ContactProblem.from_qp`) is in
    the units of d (lengths) and of f (forces).
    """
    if problem.mesh is None:
        return {"system": "the QP's own", "length": "the unit of d", "force": "the unit of f",
                "total_force": "the unit of f", "pressure": "the unit of f per unit of the weights",
                "time": "s"}
    if problem.mesh.p.shape[0] == 2 and not problem.axisymmetric:
        force = total = "stress·length (per unit thickness, plane strain)"
    else:
        total = "stress·length²"
        force = total + (" (per radian: axisymmetric)" if problem.axisymmetric else "")
    return {"system": "the scene's own (length: its lengths' unit, stress: E's unit)",
            "length": "length", "force": force, "total_force": total, "pressure": "stress",
            "time": "s"}
