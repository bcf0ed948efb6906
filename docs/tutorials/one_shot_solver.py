"""A contact solver with a deliberate flaw, for tutorial 04 (write your own solver).

It follows the package's protocol for a method,
``solve(problem, *, tol=None, max_iter=None, **options) -> signorini.ContactSolution``,
and uses only the public API (``import signorini``), so that
``signorini.crosscheck(problem, ["one_shot_solver.py:solve", "pdas"])`` and
``signorini validate --method docs/tutorials/one_shot_solver.py:solve``
can cross-check it. Its idea is the first half of an active-set method:

1. solve without contact, ``u₀ = K⁻¹ f``;
2. call every node that penetrates the obstacle (``(Nu₀ − d)ᵢ > 0``) active;
3. close those gaps exactly by solving ``[K N_Aᵀ; N_A 0] [u; λ_A] = [f; d_A]``.

The flaw: it stops there and claims success. A node that penetrated only
because its neighbours were not yet held up gets a *pulling* force ``λᵢ < 0``,
which a contact cannot exert. The certificate and the cross-check find this.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import signorini


def closed_gaps(problem: signorini.ContactProblem, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(u, λ)`` with the gaps of the ``active`` nodes closed and no force elsewhere.

    Solves ``[K N_Aᵀ; N_A 0] [u; λ_A] = [f; d_A]`` and sets ``λᵢ = 0`` off ``A``.
    """
    N_A = problem.N[active]
    system = sp.bmat([[problem.K, N_A.T], [N_A, None]], format="csc")
    solution = spla.spsolve(system, np.concatenate([problem.f, problem.d[active]]))
    lam = np.zeros(problem.m)
    lam[active] = solution[problem.n:]
    return solution[:problem.n], lam


def solve(problem: signorini.ContactProblem, *, tol: float | None = None,
          max_iter: int | None = None, **options) -> signorini.ContactSolution:
    """Close every gap the contact-free solution penetrates, in one linear solve (flawed)."""
    if options:
        raise signorini.InputError(f"one_shot_solver takes no options, got {sorted(options)}")
    u_free = spla.spsolve(sp.csc_matrix(problem.K), problem.f)
    active = problem.N @ u_free - problem.d > 0
    u, lam = closed_gaps(problem, active)
    return signorini.ContactSolution(method="one-shot", u=u, lam=lam, status="converged",
                                     iterations=1,
                                     message=f"closed the gaps of {int(active.sum())} penetrating nodes")
