"""Load control by a prescribed displacement: find the push that gives a target force.

A scene pushes its body with prescribed displacements ``s · ū_D`` (so K stays
non-singular); the load then enters affinely, ``f(s) = s f₁`` and
``d(s) = d₀ + s d₁``. For a fixed active set A the solution is affine in s
too, so the push ``s`` whose total contact force ``μ Σλ`` equals the target
``P`` solves one scalar equation per active set. Iterating the active set by
the PDAS rule gives a semismooth Newton method for the augmented system

    K u + N_Aᵀ λ_A = s f₁,   N_A u = d₀,A + s d₁,A,   μ Σ λ_A = P,

one factorisation (two right-hand sides) per step, exact when A repeats.
"""

from __future__ import annotations

import logging
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.numerics.active_set import ActiveSetSolver
from signorini.numerics.lcp import forces_on
from signorini.numerics.factor import count

log = logging.getLogger(__name__)


PairSolve = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
LoadPair = Callable[[np.ndarray], np.ndarray]


def summed(multiplicity: float, weights: np.ndarray | None = None) -> LoadPair:
    """The load of a model's contact forces: ``μ Σλ`` (μ copies of the model make the body), or
    their resultant along the push ``μ Σ cᵢλᵢ`` with the candidates' ``weights`` cᵢ."""
    if weights is None:
        return lambda lam: multiplicity * lam.sum(axis=0)
    return lambda lam: multiplicity * (weights @ lam)


def first_contact(d0: np.ndarray) -> np.ndarray:
    """The candidates that touch first (smallest initial gap): where the iteration starts."""
    return d0 <= np.min(d0)


def push_for_load(solve_pair: PairSolve, active: np.ndarray, target: float, load: LoadPair,
                  max_iter: int = 100, empty_allowed: bool = False) -> tuple[float, np.ndarray]:
    """The push ``s`` at which the load is ``target``, and the contact forces then.

    The one active-set iteration of the package's load targeting (the full
    system, the condensed problem and the zone kernel's band all use it).
    ``solve_pair(A)`` returns, for the active set A, two columns of contact
    forces and two of constraint values ``Nu − d`` such that at push s they
    are ``s·[:, 0] + [:, 1]``; ``load(λ pair)`` the two columns of the load
    (per unit push, fixed), which is linear in λ. The iteration starts from
    ``active`` and ends when the active set repeats (exact); an empty active
    set ends it unless ``empty_allowed`` (something else then carries the
    load). Raises InputError when no push reaches the target.
    """
    if not (np.isfinite(target) and target > 0):
        raise InputError(f"the target load must be a positive number, got {target!r}")
    seen: set[bytes] = set()
    for step in range(1, max_iter + 1):
        count("load_steps")
        lam, violation = solve_pair(active)
        per_push, fixed = load(lam)
        if not per_push > 0:
            raise InputError("pushing the body does not press it onto the obstacle: "
                             "check the scene's prescribed displacement and obstacle")
        s = (target - fixed) / per_push
        lam_s = s * lam[:, 0] + lam[:, 1]
        new_active = lam_s + (s * violation[:, 0] + violation[:, 1]) > 0
        if np.array_equal(new_active, active):
            log.info("push found in %d active-set steps (s = %.6g)", step, s)
            return float(s), lam_s
        if new_active.tobytes() in seen or not (new_active.any() or empty_allowed):
            break
        seen.add(active.tobytes())
        active = new_active
    raise InputError("the target load could not be matched by adjusting the prescribed "
                     "displacement (active set did not settle): try delta= instead of P=")


def condensed_pair(W: np.ndarray, b_pair: np.ndarray) -> PairSolve:
    """Pairs of the condensed problem ``Wλ − b ≥ 0`` (dense work only, no back-solve)."""

    def solve_pair(active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        try:
            lam = forces_on(W, b_pair, active)
        except sla.LinAlgError as exc:
            raise ArithmeticError("the contact operator is singular on the active set") from exc
        return lam, b_pair - W @ lam

    return solve_pair


def calibrate_push(K: sp.csr_matrix, N: sp.csr_matrix, f1: np.ndarray, d0: np.ndarray,
                   d1: np.ndarray, target: float, multiplicity: float = 1.0,
                   f0: np.ndarray | None = None, start: np.ndarray | None = None,
                   weights: np.ndarray | None = None,
                   system: ActiveSetSolver | None = None) -> tuple[float, np.ndarray, np.ndarray]:
    """The push on the full sparse system (one factorisation per active set); λ and u then.

    The load is ``s f1 + f0`` (``f0``, e.g. a traction, does not change with the
    push). The iteration starts from the active set ``start`` (e.g. the zone an
    analytic estimate predicts: a good guess leaves one or two steps) or from
    the first point(s) of contact. The load is the forces' resultant along the
    push (:func:`summed` with the candidates' ``weights``). ``system`` (an
    :class:`ActiveSetSolver` of K and N) is the caller's to keep: its ``factor`` is then the
    last active set's factorisation, for a method to reuse.
    """
    system = ActiveSetSolver(K, N) if system is None else system
    f_pair = np.column_stack([f1, np.zeros_like(f1) if f0 is None else f0])
    d_pair = np.column_stack([d1, d0])
    last: dict[str, np.ndarray] = {}

    def solve_pair(active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        last["u"], lam = system.solve(active, f_pair, d_pair)
        return lam, N @ last["u"] - d_pair

    first = first_contact(d0) if start is None or not start.any() else start
    s, lam = push_for_load(solve_pair, first, target, summed(multiplicity, weights))
    return s, lam, last["u"] @ [s, 1.0]


def push_for_load_condensed(W: np.ndarray, b1: np.ndarray, b0: np.ndarray, d0: np.ndarray,
                            target: float, multiplicity: float = 1.0) -> tuple[float, np.ndarray]:
    """The push on the condensed problem, ``b(s) = s b₁ + b₀``: dense work only, no back-solve."""
    return push_for_load(condensed_pair(W, np.column_stack([b1, b0])), first_contact(d0), target,
                         summed(multiplicity))


__all__ = ["summed", "first_contact", "push_for_load", "condensed_pair", "calibrate_push",
           "push_for_load_condensed"]
