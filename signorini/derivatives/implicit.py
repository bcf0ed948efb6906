"""Derivatives of the contact answer, by implicit differentiation of the KKT conditions.

On the final active set A the answer solves the linear system

    K u + N_Aᵀ λ_A = f,    N_A u = d_A,    λ = 0 off A,

so a change ``(df, dd)`` of the data moves it by the solution of the same system,
``[K N_Aᵀ; N_A 0] [du; dλ_A] = [df; dd_A]``: with the factorisation a method
already holds, back-solves only. The matrix is symmetric, so the adjoint
(``vjp``) is the same solve. A change of K enters as ``df = −dK u``.

A weakly active candidate (gap 0 and force 0) may enter or leave the contact:
there the answer is differentiable from one side only. ``side="auto"`` gives
the directional derivative along ``+(df, dd)`` (a node presses when its gap
would close, and lets go when its force would turn negative), ``"in"`` and
``"out"`` keep every weak node in or out of A; every answer lists the weak nodes.

:mod:`signorini.derivatives.scene` differentiates a scene's physical outputs with respect
to its parameters on this system.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from signorini.errors import InputError, SolverError
from signorini.certification.kkt import ACTIVE, WEAK, classify
from signorini.numerics.active_set import ActiveSetSolver
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.reprs import short_repr

SIDES = ("auto", "in", "out")


class _Pair:
    """A derivative that unpacks as the pair of its first two fields; one-sided where some
    candidates are ``weakly_active`` (touching with zero force)."""

    __repr__ = short_repr

    def __iter__(self):
        return iter([getattr(self, field.name) for field in fields(self)[:2]])

    @property
    def one_sided(self) -> bool:
        return bool(self.weakly_active.size)


@dataclass(frozen=True, repr=False)
class Tangent(_Pair):
    """``(du, dforce)`` from :meth:`Result.jvp <signorini.api.Result.jvp>`; ``pressed`` says
    which of the ``weakly_active`` candidates were kept in contact."""

    du: np.ndarray
    dforce: np.ndarray
    weakly_active: np.ndarray
    pressed: np.ndarray


@dataclass(frozen=True, repr=False)
class Cotangent(_Pair):
    """``(gf, gd)`` from :meth:`Result.vjp <signorini.api.Result.vjp>`; ``side`` is the branch at
    the ``weakly_active`` candidates (``in``: kept in contact, ``out``: let go)."""

    gf: np.ndarray
    gd: np.ndarray
    weakly_active: np.ndarray
    side: str


class Sensitivity:
    """The KKT system of one answer on its active set, factorised once, in the problem's units.

    ``factor`` is a factorisation the method holds (reused when it pins this
    very active set, else let go before another is made); otherwise the first
    solve makes one and later ones reuse it.
    """

    def __init__(self, problem: ContactProblem, solution: ContactSolution, factor: Any = None):
        exact_answer(solution)
        self.problem, self.solution = problem, solution
        labels = classify(problem, solution)
        self.strong = labels == ACTIVE
        self.weak = np.flatnonzero(labels == WEAK)
        self._system = ActiveSetSolver(problem.K, problem.N)
        self._factor = factor

    def solve(self, active: np.ndarray, f: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(du, dλ)`` on ``active`` (f: n or n × k, d: m or m × k), reusing the factorisation."""
        if not self._system.pins(active, self._factor):
            self._factor = None  # not this system's: let go before the solve makes another
        du, dlam = self._system.solve(active, f, d, factor=self._factor)
        if self._system.factor is not None:
            self._factor = self._system.factor
        return du, dlam

    def branch(self, side: str) -> np.ndarray:
        """The active set with every weak node in (``in``) or out (``out``)."""
        active = self.strong.copy()
        if side == "in":
            active[self.weak] = True
        return active

    def tangent(self, df: np.ndarray, dd: np.ndarray, side: str = "auto") -> tuple[np.ndarray, ...]:
        """``(du, dλ, pressed)`` for the change ``(df, dd)``; see the module's note on ``side``."""
        side = _side(side, SIDES)
        active = self.branch("out" if side == "auto" else side)
        du, dlam = self.solve(active, df, dd)
        if side == "auto":
            for _ in range(self.weak.size):  # a small active-set loop over the weak nodes only
                closing = (dd - self.problem.N @ du)[self.weak] < 0
                pulling = dlam[self.weak] < 0
                wanted = active.copy()
                wanted[self.weak[closing & ~active[self.weak]]] = True
                wanted[self.weak[pulling & active[self.weak]]] = False
                if np.array_equal(wanted, active):
                    break
                active = wanted
                du, dlam = self.solve(active, df, dd)
        return du, dlam, self.weak[active[self.weak]]

    def cotangent(self, gu: np.ndarray, glam: np.ndarray, side: str = "out") -> tuple[np.ndarray, ...]:
        """``(gf, gd)`` with ``⟨gu, du⟩ + ⟨gλ, dλ⟩ = ⟨gf, df⟩ + ⟨gd, dd⟩`` on one branch."""
        side = _side(side, ("in", "out"))
        active = self.branch(side)
        glam = np.where(active, glam, 0.0)
        gf, gd = self.solve(active, gu, glam)
        return gf, np.where(active, gd, 0.0)


def exact_answer(solution: ContactSolution) -> None:
    """SolverError unless ``solution`` is converged and finite: only an exact answer has a
    derivative (a ``max_iter`` answer's active set may not be the answer's)."""
    if solution.status != "converged":
        raise SolverError(f"the answer is {solution.status} ({solution.message}): only an exact "
                          "answer has a derivative; solve to convergence first")
    if not (np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))):
        raise SolverError("the answer is not finite: it has no derivative")


def _side(side: str, allowed: tuple[str, ...]) -> str:
    if side not in allowed:
        raise InputError(f"side must be one of {', '.join(allowed)}, got {side!r}")
    return side


def _vector(value: Any, size: int, name: str, unit: float) -> np.ndarray:
    if value is None:
        return np.zeros(size)
    try:
        array = np.asarray(value)
    except ValueError:  # a ragged list
        array = np.asarray(None)
    if array.dtype.kind not in "biuf":
        raise InputError(f"{name} must be {size} real numbers, got {str(value)[:60]}")
    array = array.astype(float)
    if array.shape != (size,):
        raise InputError(f"{name} must have shape ({size},), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} contains non-finite values")
    return array / unit


def jvp(sensitivity: Sensitivity, df: Any = None, dd: Any = None, side: str = "auto") -> Tangent:
    """``(du, dforce)`` for a change ``(df, dd)`` of the QP's load and gaps, in the user's units.

    ``df`` is in force units (n free dofs), ``dd`` in length units (m
    candidates); ``du`` in length units, ``dforce`` the nodal contact forces.
    """
    problem = sensitivity.problem
    s = problem.scales
    du, dlam, pressed = sensitivity.tangent(_vector(df, problem.n, "df", s.force),
                                            _vector(dd, problem.m, "dd", s.displacement), side)
    return Tangent(du * s.displacement, dlam * s.force, sensitivity.weak, pressed)


def vjp(sensitivity: Sensitivity, gu: Any = None, gforce: Any = None, side: str = "out") -> Cotangent:
    """``(gf, gd)``: the gradient of ``⟨gu, u⟩ + ⟨gforce, force⟩`` with respect to f and d."""
    problem = sensitivity.problem
    s = problem.scales
    gf, gd = sensitivity.cotangent(_vector(gu, problem.n, "gu", 1 / s.displacement),
                                   _vector(gforce, problem.m, "gforce", 1 / s.force), side)
    return Cotangent(gf / s.force, gd / s.displacement, sensitivity.weak, side)


__all__ = ["Cotangent", "SIDES", "Sensitivity", "Tangent", "exact_answer", "jvp", "vjp"]
