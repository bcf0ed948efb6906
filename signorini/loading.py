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

import numpy as np
import scipy.sparse as sp

from .errors import InputError
from .linalg import ActiveSetSolver

log = logging.getLogger(__name__)


def calibrate_push(K: sp.csr_matrix, N: sp.csr_matrix, f1: np.ndarray, d0: np.ndarray,
                   d1: np.ndarray, target: float, multiplicity: float = 1.0,
                   max_iter: int = 100) -> float:
    """The factor ``s`` on the prescribed displacement whose contact force is ``target``.

    Raises InputError when the target is not positive or no push reaches it.
    """
    if not (np.isfinite(target) and target > 0):
        raise InputError(f"the target load must be a positive number, got {target!r}")
    active = d0 <= np.min(d0)  # start from the first point(s) of contact
    seen: set[bytes] = set()
    system = ActiveSetSolver(K, N)
    for step in range(1, max_iter + 1):
        u, lam = system.solve(active, np.column_stack([f1, np.zeros_like(f1)]),
                              np.column_stack([d1, d0]))
        per_push, fixed = multiplicity * lam.sum(axis=0)
        if not per_push > 0:
            raise InputError("pushing the body does not press it onto the obstacle: "
                             "check the scene's prescribed displacement and obstacle")
        s = (target - fixed) / per_push
        u_s, lam_s = s * u[:, 0] + u[:, 1], s * lam[:, 0] + lam[:, 1]
        violation = N @ u_s - (d0 + s * d1)
        new_active = lam_s + violation > 0
        if np.array_equal(new_active, active):
            log.info("push calibrated in %d active-set steps (s = %.6g)", step, s)
            return float(s)
        if new_active.tobytes() in seen or not new_active.any():
            break
        seen.add(active.tobytes())
        active = new_active
    raise InputError("the target load could not be matched by adjusting the prescribed "
                     "displacement (active set did not settle): try delta= instead of P=")
