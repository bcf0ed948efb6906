"""What makes a contact problem ill-posed, what is wrong with an answer, by constraint.

:func:`diagnose` names, one sentence each, what makes
``min ½uᵀKu − fᵀu, Nu ≤ d`` infeasible or ill-posed (a candidate the
Dirichlet data already push through the obstacle, a candidate listed twice,
a singular K); :func:`regularise` adds a weak spring to every free dof so
that the methods that need ``K⁻¹`` can run on a body held only by contact.
The stability atlas (axes 6 and 8, ``docs/stability.md``) measures both.
:func:`violations` and :func:`explain` say which candidates an answer fails and how
(penetration, tension, complementarity, stationarity), with the advice that fits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.certification.kkt import force_scale, gap_scale
from signorini.problem.contact import ContactProblem, ContactSolution

#: the kinds of failure of a candidate, in the order a message names them
KINDS = ("penetration", "tension", "complementarity", "stationarity")
#: candidates named in a message, per kind
NAMED = 3


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
    new = problem.with_data(K=K, params={**problem.model.params, "regularisation": float(epsilon)})
    new.model.basis = problem.model.basis
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
                        "signorini.certification.diagnosis.regularise(problem, 1e-8)")
    return findings


@dataclass(frozen=True)
class Violation:
    """Candidate ``index`` fails ``kind`` by ``size`` (relative, as in the certificate);
    ``force`` is its λ over the force scale, ``point`` its position (None when unknown)."""

    index: int
    kind: str
    size: float
    force: float
    point: tuple[float, ...] | None


def violations(problem: ContactProblem, solution: ContactSolution,
               accept: float) -> list[Violation]:
    """The candidates whose own residual exceeds ``accept``, the largest first within each kind.

    With ``g = Nu − d``, the gap scale ``L`` and the force scale ``Λ`` of
    :class:`signorini.certification.kkt.Certificate`: penetration ``gᵢ / L``, tension ``−λᵢ / Λ``,
    complementarity ``|λᵢ gᵢ| / (Λ L)``, and stationarity the largest
    ``|Ku − f + Nᵀλ|`` on the dofs of row i, over the certificate's stationarity scale.
    """
    u, lam = solution.u, solution.lam
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(lam))):
        return []
    N = sp.csr_matrix(problem.N)
    violation, length, force = N @ u - problem.d, gap_scale(problem, u), force_scale(problem, lam, u)
    NT_lam = N.T @ lam
    lam_norm = float(np.max(np.abs(lam), initial=0.0))
    scale = max(float(np.max(np.abs(NT_lam), initial=0.0)), force if force > lam_norm else 0.0)
    residual = np.abs(problem.K @ u - problem.f + NT_lam) / (scale or 1.0)
    on_rows = sp.csr_matrix((residual[N.indices], N.indices, N.indptr),
                            shape=N.shape).max(axis=1).toarray().ravel()
    sizes = {"penetration": violation / length, "tension": -lam / force,
             "complementarity": np.abs(lam * violation) / (force * length),
             "stationarity": on_rows}
    points = problem.contact_points
    found = []
    for kind in KINDS:
        for i in np.argsort(-sizes[kind], kind="stable"):
            if not sizes[kind][i] > accept:
                break
            point = None if points is None or np.isnan(points[i]).any() else \
                tuple(float(x) * problem.scales.length for x in points[i])
            found.append(Violation(int(i), kind, float(sizes[kind][i]), float(lam[i] / force),
                                   point))
    return found


def _named(found: list[Violation]) -> str:
    said = [f"{v.index}" + (f" at ({', '.join(f'{x:.3g}' for x in v.point)})" if v.point else "")
            + f", by {v.size:.1e}" for v in found[:NAMED]]
    return ", ".join(said) + (f" and {len(found) - NAMED} more" if len(found) > NAMED else "")


def explain(problem: ContactProblem, solution: ContactSolution, accept: float) -> str | None:
    """Which candidates ``solution`` fails and how, with the advice that fits each kind
    (:func:`violations`); None when no candidate fails on its own."""
    found = violations(problem, solution, accept)
    said = []
    ignored = [v for v in found if v.kind == "penetration" and v.force <= accept]
    pressing = [v for v in found if v.kind == "penetration" and v.force > accept]
    if ignored:
        rows = ", ".join(str(v.index) for v in ignored[:NAMED])
        said.append(f"constraint {rows} ignored: penetration with no contact force at candidate "
                    f"{_named(ignored)}; the method must enforce every row of N u ≤ d (row {rows} "
                    "included): a tighter tolerance will not help")
    if pressing:
        said.append(f"penetration where it presses at candidate {_named(pressing)}: the force "
                    "is too small there; iterate further (tol, max_iter) or use an exact method "
                    "(pdas)")
    advice = {"tension": "tension (λ < 0) at candidate {}: a contact force pushes (λ ≥ 0 for "
                         "N u ≤ d); release a candidate whose force turns negative, or check "
                         "the sign of λ",
              "complementarity": "force at a distance at candidate {}: λ > 0 where the gap is "
                                 "open; a candidate apart must carry no force",
              "stationarity": "no equilibrium at candidate {}: K u − f + Nᵀλ ≠ 0 on its dofs; "
                              "u must solve K u = f − Nᵀλ for the λ returned (check the linear "
                              "solve and that λ is the force on N u ≤ d)"}
    for kind, text in advice.items():
        of_kind = [v for v in found if v.kind == kind]
        if of_kind:
            said.append(text.format(_named(of_kind)))
    return "; ".join(said) or None


__all__ = ["KINDS", "Violation", "diagnose", "explain", "regularise", "violations"]
