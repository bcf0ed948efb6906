"""What makes a contact problem ill-posed, and the package's handling of a singular K.

:func:`diagnose` names, one sentence each, what makes
``min ½uᵀKu − fᵀu, Nu ≤ d`` infeasible or ill-posed (a candidate the
Dirichlet data already push through the obstacle, a candidate listed twice,
a singular K); :func:`regularise` adds a weak spring to every free dof so
that the methods that need ``K⁻¹`` can run on a body held only by contact.
The stability atlas (axes 6 and 8, ``docs/stability.md``) measures both.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.problem import ContactProblem


def regularise(problem: ContactProblem, epsilon: float) -> ContactProblem:
    """``K + ε k̄ I`` with ``k̄ = mean |diag K|``: a weak spring on every free dof.

    For a body held only by contact (force control) ``K`` is singular and
    methods that need ``K⁻¹`` (PDAS, Uzawa, the condensed dual) cannot start;
    with the springs it is SPD. The springs carry the force
    ``ε k̄ Σᵢ uᵢ`` that the contact no longer does, so the answer moves by
    about ``ε k̄ ‖u‖₁ / ‖f‖₁`` (relative; the atlas measures it, see
    ``docs/stability.md``): ε = 1e-8 changes λ by about 1e-6 on the 8 × 8
    force-controlled block, and every method but Uzawa then solves it.

    Parameters
    ----------
    problem : the contact problem (its K may be singular).
    epsilon : the relative spring stiffness, a finite number > 0.

    Returns
    -------
    ContactProblem
        a copy with the regularised K and ``params["regularisation"] = epsilon``.
    """
    if isinstance(epsilon, bool) or not isinstance(epsilon, (int, float, np.floating)) \
            or not (math.isfinite(epsilon) and epsilon > 0):
        raise InputError(f"regularisation epsilon={epsilon!r} must be a finite number > 0, "
                         "e.g. 1e-8")
    stiffness = float(np.mean(np.abs(problem.K.diagonal()))) or 1.0
    K = (problem.K + epsilon * stiffness * sp.identity(problem.n, format="csr")).tocsr()
    new = problem.with_data(K=K, params={**problem.params, "regularisation": float(epsilon)})
    new.basis = problem.basis
    return new


def diagnose(problem: ContactProblem) -> list[str]:
    """What makes ``min ½uᵀKu − fᵀu, Nu ≤ d`` infeasible or ill-posed, one sentence each.

    - a row ``Nᵢ = 0`` (every dof of candidate i prescribed) with ``dᵢ < 0``:
      the prescribed displacement already penetrates the obstacle, no u can
      satisfy ``0 ≤ dᵢ`` — infeasible;
    - a row ``Nᵢ = 0`` with ``dᵢ ≥ 0``: the constraint is void;
    - two equal rows: the two forces are not unique, only their sum is;
    - ``K`` not positive definite: a rigid mode that only the contact can
      hold (force control); methods that need ``K⁻¹`` cannot run.

    Returns an empty list when none applies.
    """
    findings: list[str] = []
    N = sp.csr_matrix(problem.N, copy=True)
    N.eliminate_zeros()
    empty = np.nonzero(np.diff(N.indptr) == 0)[0]
    scale = problem.scales.displacement
    penetrated = empty[problem.d[empty] < 0]
    if penetrated.size:
        shown = ", ".join(str(i) for i in penetrated[:5]) + (", …" if penetrated.size > 5 else "")
        findings.append(
            f"infeasible: {penetrated.size} contact candidate(s) ({shown}) have every dof "
            "prescribed and the prescribed displacement already penetrates the obstacle (by up "
            f"to {-problem.d[penetrated].min() * scale:.3g}): no displacement satisfies Nu ≤ d; "
            "move the obstacle or change the Dirichlet data")
    if np.any(problem.d[empty] >= 0):
        count = int(np.sum(problem.d[empty] >= 0))
        findings.append(f"{count} contact candidate(s) have every dof prescribed: their "
                        "constraints are constant; leave them out of the candidates")
    rows = {}
    for i in range(problem.m):
        key = (N.indices[N.indptr[i]:N.indptr[i + 1]].tobytes(),
               np.round(N.data[N.indptr[i]:N.indptr[i + 1]], 12).tobytes())
        if N.indptr[i + 1] > N.indptr[i] and key in rows:
            findings.append(f"ill-posed: contact candidates {rows[key]} and {i} constrain the same "
                            "dofs in the same direction: their forces are not unique (only the "
                            "sum is); list each node once")
            break
        rows.setdefault(key, i)
    try:
        problem.factor()
    except (np.linalg.LinAlgError, ArithmeticError, RuntimeError) as exc:
        findings.append(f"K is singular ({exc}): a rigid mode is held only by the contact; pdas, "
                        "uzawa and condensed need K⁻¹ — prescribe a displacement or use "
                        "signorini.diagnose.regularise(problem, 1e-8)")
    return findings
