"""Two answers of one problem compared, and a reference answer refined beyond double precision.

For studies, tests and cross-checks, never for the certificate (:mod:`signorini.certification.kkt`):
how far two answers are apart, their active sets included (:func:`compare`), and the answer on
an active set refined in long double (:func:`refined_on_active_set`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import scipy.sparse as sp

from signorini.certification.inverse import Counted, newton_system
from signorini.certification.kkt import WEAK, WEAK_TOL, classify, inf_norm
from signorini.problem.contact import ContactProblem, ContactSolution


@dataclass(frozen=True)
class Comparison:
    """How far two solutions of one problem are apart.

    ``u_rel`` and ``lam_rel`` are ∞-norm differences relative to the larger
    norm; ``misclassified`` counts nodes active in one and inactive in the
    other (weakly active nodes of either are left out and counted in ``weak``).
    """

    u_rel: float
    lam_rel: float
    misclassified: int
    weak: int

    @property
    def same_active_set(self) -> bool:
        return self.misclassified == 0

    as_dict = asdict


def _rel_diff(a: np.ndarray, b: np.ndarray) -> float:
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return float("inf")
    return inf_norm(a - b) / (max(inf_norm(a), inf_norm(b)) or 1.0)


def compare(problem: ContactProblem, first: ContactSolution, second: ContactSolution,
            weak_tol: float = WEAK_TOL) -> Comparison:
    """Compare two solutions: displacements, multipliers and active sets."""
    u_rel, lam_rel = _rel_diff(first.u, second.u), _rel_diff(first.lam, second.lam)
    if not np.isfinite(lam_rel) or not np.isfinite(u_rel):
        return Comparison(u_rel, lam_rel, problem.m, 0)
    a, b = classify(problem, first, weak_tol), classify(problem, second, weak_tol)
    weak = (a == WEAK) | (b == WEAK)
    misclassified = int(np.sum((a != b) & ~weak))
    return Comparison(u_rel, lam_rel, misclassified, int(np.sum(weak)))


def refined_on_active_set(K: sp.spmatrix, f: np.ndarray, N: sp.csr_matrix, d: np.ndarray,
                          u: np.ndarray, lam: np.ndarray, active: np.ndarray, factor,
                          steps: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """``(u*, λ*)`` on ``active`` by iterative refinement with residuals in ``np.longdouble``.

    The corrections come from ``factor`` in double precision (as in
    :func:`~signorini.certification.inverse.forward_error`); the residuals and the sums are long
    double (80-bit on x86: 11 more bits), so the refinement converges below double's round-off
    wherever ``κ(M) ε_double < 1``. A reference for tests and studies, not for the
    certificate (each step is a long-double product with K).
    """
    ld = np.longdouble
    rows = np.flatnonzero(active)
    apply = newton_system(K, N, rows, Counted(factor))
    if apply is None:
        raise np.linalg.LinAlgError("no Newton step on this active set: its rows of N are "
                                    "dependent, or too many to border")
    K_l, N_l = K.astype(ld), N[rows].astype(ld)
    f_l, d_l = f.astype(ld), d[rows].astype(ld)
    x, mu = u.astype(ld), lam[rows].astype(ld)
    for _ in range(steps):
        r = K_l @ x - f_l + N_l.T @ mu
        g = N_l @ x - d_l
        du, dmu = apply(r.astype(float), g.astype(float))
        x, mu = x + du.astype(ld), mu + dmu.astype(ld)
    out = np.zeros(lam.shape, dtype=ld)
    out[rows] = mu
    return x, out


__all__ = ["Comparison", "compare", "refined_on_active_set"]
