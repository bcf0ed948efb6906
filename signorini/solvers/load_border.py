"""A pending target load as one more unknown of ``pdas-amg``'s CG systems: no factorisation.

A scene pushed towards a target load P (``problem.model.pending``) whose pushed
dofs move together has a load row parallel to the push's forces, so the
push ``s`` joins the displacement as one more unknown of a symmetric
system, SPD once the contact holds the body (:class:`LoadBorder`). CG
preconditions it by block elimination with the method's multigrid
(:func:`border_preconditioner`). :class:`Unknowns` is what CG solves for at
each active-set step, with the border or without: the Newton loop of
:mod:`signorini.solvers.amg` reads the same either way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from signorini.numerics.multigrid import Bordered
from signorini.problem.contact import ContactProblem
from signorini.solvers.bounds import BoundForm


@dataclass
class LoadBorder:
    """Load targeting without a factorisation: the push ``s`` as one more unknown.

    The pushed dofs move together, so the load row is parallel to the push's
    forces, ``ℓ = β f₁``, and the target ``ℓ·u + s·o₁ + o₀ = P`` is the last
    row of the symmetric system ``[[K, −f₁], [−f₁ᵀ, −o₁/β]] [u; s] = [f₀;
    −(P − o₀)/β]``: K of the body with the pushed dofs as one more unknown,
    SPD once the contact holds it (:class:`~signorini.numerics.multigrid.Bordered`).
    CG preconditions it by block elimination (:func:`border_preconditioner`).
    Arrays are the bound form's (rotated, full length).
    """

    g: np.ndarray  # the push's forces f₁
    k: float  # −o₁/β
    h: float  # −(P − o₀)/β
    f0: np.ndarray  # the load that does not move with the push
    beta: float
    target: float
    push: float  # the nominal push: where CG starts without a better guess


def border_factor(problem: ContactProblem) -> float | None:
    """β of :class:`LoadBorder` for a problem whose target load is pending, or None (nothing
    pending, the pushed dofs do not move together, or the push moves a contact candidate)."""
    pu = problem.model.push
    if not problem.model.pending or problem.model.load_row is None or np.any(pu.d1 != 0):
        return None
    f1, row = pu.f1, problem.model.load_row
    beta = float(row @ f1) / max(float(f1 @ f1), 1e-300)
    if not beta or np.linalg.norm(row - beta * f1) > 1e-9 * np.linalg.norm(row):
        return None
    return beta if -pu.offset1 / beta > 0 else None


def load_border(problem: ContactProblem, form: BoundForm) -> LoadBorder | None:
    """The border of a problem whose target load is pending (see :func:`border_factor`)."""
    beta = border_factor(problem)
    if beta is None:
        return None
    pu = problem.model.push
    fixed = pu.load * pu.f_load if pu.f_load is not None else np.zeros(problem.n)
    return LoadBorder(g=rotated(form, pu.f1), k=-pu.offset1 / beta,
                      h=-(pu.target - pu.load * pu.offset_load) / beta, f0=rotated(form, fixed),
                      beta=beta, target=pu.target, push=pu.scale)


def border_preconditioner(apply, border: LoadBorder):
    """The multigrid ``M ≈ A⁻¹`` extended to the bordered matrix ``[[A, −g], [−gᵀ, k]]``.

    Block elimination with ``w = −M g`` (one V-cycle, once) and the Schur
    complement ``S = k − gᵀ M g``: ``P = Z diag(M, 1/S) Zᵀ``, ``Z = [[I, w], [0, 1]]``,
    symmetric positive definite for any w when S > 0 and the exact inverse
    when M is (what it saves CG is in docs/amg.md). Should S not be clearly positive
    (M too far from A⁻¹), the border's diagonal alone.
    """
    Mg = apply(border.g)
    schur = border.k - float(border.g @ Mg)
    if not schur > 1e-3 * border.k:
        return lambda r: np.append(apply(r[:-1]), r[-1] / border.k)

    def precondition(r: np.ndarray) -> np.ndarray:
        t = (r[-1] + float(Mg @ r[:-1])) / schur
        return np.append(apply(r[:-1]) + Mg * t, t)

    return precondition


def rotated(form: BoundForm, v: np.ndarray) -> np.ndarray:
    """A vector on the problem's free dofs in the bound form's (rotated, full-length) dofs."""
    full = np.zeros(form.T.shape[0])
    full[form.free_dofs] = v
    return form.T.T @ full


class Unknowns:
    """What CG solves for at each active-set step: the bound form's dofs ``x``, and the push
    last when a pending load is bordered (``border``; starting at ``push0``, else the nominal
    push).

    ``system`` is the method's pinned system (its ``form``, ``product`` ``K @ x`` and multigrid
    ``hierarchy``); ``values`` the array CG updates, ``x`` its displacement part.
    """

    def __init__(self, system, border: LoadBorder | None = None, push0: float | None = None):
        self.border, form = border, system.form
        self.values = np.zeros(form.n + (border is not None))
        self.x = self.values[:form.n]
        self.operator, self.rhs = system.product, form.f
        self.precondition = system.hierarchy.apply
        if border is not None:
            self.values[-1] = border.push if push0 is None else float(push0)
            self.operator = Bordered(system.product, border.g, border.k)
            self.rhs = np.append(border.f0, border.h)
            self.precondition = border_preconditioner(system.hierarchy.apply, border)

    @property
    def push(self) -> float | None:
        """The push found with the answer (None without a border)."""
        return None if self.border is None else float(self.values[-1])

    def free(self, free: np.ndarray) -> np.ndarray:
        """CG's free mask: the free dofs, and the push."""
        return free if self.border is None else np.append(free, True)

    def weights(self, force: float) -> np.ndarray | None:
        """The residual's weights: the load row weighed as its relative error times ``force``."""
        if self.border is None:
            return None
        weights = np.ones(self.values.size)
        weights[-1] = abs(self.border.beta) * force / self.border.target
        return weights

    def loaded(self, f: np.ndarray) -> np.ndarray:
        """The bound form's load at the push found (``f`` itself without a border)."""
        return f if self.border is None else self.border.f0 + self.values[-1] * self.border.g

    def at_push(self, problem: ContactProblem) -> ContactProblem:
        """``problem`` at the push found (itself without a border): what the answer solves."""
        return problem if self.border is None else problem.pushed(float(self.values[-1]))


__all__ = ["LoadBorder", "Unknowns", "border_factor", "border_preconditioner", "load_border",
           "rotated"]


