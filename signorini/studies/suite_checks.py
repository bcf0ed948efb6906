"""The validation suite's claims: the limits a case is held to, and the checks of one case.

A check is one claim the suite stands behind (a reference's own claims, λ and the active set of
every converged run against the exact ``pdas`` answer, the paper's Uzawa converged and agreeing
with two QP backends); any failed check fails the suite (:mod:`signorini.studies.suite`).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from signorini.crosschecking import agreement
from signorini.errors import InputError
from signorini.paths import check_input_file
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.problem.files import is_problem_file
from signorini.references.catalogue import reference_metrics, reference_of
from signorini.scenes.base import Case
from signorini.studies.runner import Row

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["CROSS_CHECKED", "LIMITS", "REFERENCE_LABEL", "REFERENCE_METHOD", "TIGHT_TOL", "CaseResult",
           "Check", "case_checks", "cross_checks", "label", "read_limits"]

REFERENCE_METHOD = "pdas"
TIGHT_TOL = 1e-9
#: the label of the run that is the reference's own method at the tight tolerance
REFERENCE_LABEL = f"{REFERENCE_METHOD}@{TIGHT_TOL:.0e}"
#: the paper's method, cross-checked on every case against the two named QP backends in their
#: default formulation (signorini.crosschecking.agreement): both must converge and agree
CROSS_CHECKED = ("uzawa", ("qp-osqp", "qp-clarabel"))

#: the claims the suite checks, with their limits
LIMITS = {
    "hertz_p0_rel": 0.01,
    "hertz_a_rel": 0.01,
    "hertz_pressure_l2_rel": 0.03,
    "force_balance": 1e-8,
    "uniform_pressure_rel": 1e-8,
    "lam_rel_vs_pdas": 1e-6,
    "units_invariance": 1e-8,
    # the 3D sphere (P1 tetrahedra, quarter model): coarser by design, see docs/spheres.md
    "hertz_3d_p0_rel": 0.03,
    "hertz_3d_a_rel": 0.03,
    "hertz_3d_pressure_l2_rel": 0.06,
    # two models of one body (axisymmetric and 3D sphere): a and p0 agree
    "models_agree_rel": 0.03,
    # flat punch: nodal pressure against P/(π√(a² − x²)) on |x| ≤ a/2, away from the singular edges
    "punch_pressure_rel": 0.01,
    # the contact resultant equals the target load
    "load_target_rel": 1e-8,
}


@dataclass
class Check:
    """One claim of the suite: ``value`` must be at most ``limit`` (or true)."""

    case: str
    name: str
    value: float | bool
    limit: float | None
    passed: bool
    detail: str = ""


@dataclass
class CaseResult:
    """A case's problem, the reference solution, every run and its answer (by the run's label)."""

    case: Case
    problem: ContactProblem
    reference: ContactSolution
    solutions: dict[str, ContactSolution]
    runs: list[Row]


def label(method: str, tol: float | None) -> str:
    """A run's name in the report: ``pdas@1e-09``, ``qp-osqp@default``."""
    return f"{method}@{'default' if tol is None else f'{tol:.0e}'}"


def case_checks(result: CaseResult, by_name: dict[str, CaseResult],
                required: tuple[str, ...] = (), tol: float = TIGHT_TOL,
                limits: dict[str, float] = LIMITS) -> list[Check]:
    """The suite's claims about one case; ``required`` methods must converge at ``tol``.

    On a user's problem file (:func:`problem_case`) the claims about the package's own
    methods (the paper's Uzawa converges and agrees with two QP backends) are not made:
    the suite judges the methods run against the exact answer.
    """
    case, problem, ref = result.case, result.problem, result.reference
    own_case = not is_problem_file(case.scene)
    checks: list[Check] = []

    def holds(name: str, ok: bool, detail: str = "") -> None:
        checks.append(Check(case.name, name, ok, None, ok, detail))

    def limit(name: str, value: float | None, key: str, detail: str = "") -> None:
        value = float("nan") if value is None else float(value)  # None: not finite in a row
        checks.append(Check(case.name, name, value, limits[key],
                            bool(np.isfinite(value) and value <= limits[key]), detail))

    holds("pdas converged", ref.status == "converged", ref.message)

    metrics = reference_metrics(problem, ref) if case.check_reference else {}
    reference = reference_of(problem)
    if metrics and reference is not None and reference.claims is not None:
        for claim in reference.claims(problem, ref, metrics):  # the reference's own claims
            if claim.limit is not None:
                limit(claim.name, claim.value, claim.limit, claim.detail)
            else:
                holds(claim.name, bool(claim.value), claim.detail)
    if case.agrees_with and case.agrees_with in by_name and metrics:
        other = by_name[case.agrees_with]
        theirs = reference_metrics(other.problem, other.reference)
        for key in ("p0", "a"):
            if theirs:
                diff = abs(metrics[key] / theirs[key] - 1.0)
                limit(f"{key} agrees with that of {case.agrees_with} (pdas)", diff, "models_agree_rel")
    for row in result.runs:
        # the reference's own method at the reference's tolerance would be compared with itself
        if row["label"] == REFERENCE_LABEL:
            continue
        if row["tol"] == tol and row["status"] == "converged" and "vs_reference" in row:
            vs = row["vs_reference"]
            limit(f"{row['label']} converged: λ agrees with pdas", vs["lam_rel"], "lam_rel_vs_pdas")
            holds(f"{row['label']} converged: same active set as pdas", vs["misclassified"] == 0,
                  f"{vs['misclassified']} nodes misclassified")
    must_converge = {}
    if own_case:
        checks += cross_checks(result, tol)
        must_converge["uzawa"] = "uzawa (the paper's method) converged"
    must_converge.update({name: f"{name} (asked for by name) converged" for name in required})
    for row in result.runs:
        if row["method"] in must_converge and row["tol"] == tol:
            holds(must_converge[row["method"]], row["status"] == "converged", row["message"])
    if case.same_as and case.same_as in by_name:
        other = by_name[case.same_as].reference
        diff = float(np.max(np.abs(other.lam - ref.lam)) / np.max(np.abs(other.lam)))
        limit(f"dimensionless λ equals that of {case.same_as}", diff, "units_invariance")
    return checks


def cross_checks(result: CaseResult, tol: float = TIGHT_TOL) -> list[Check]:
    """Uzawa against each of :data:`CROSS_CHECKED`'s QP backends at ``tol``.

    A check for each backend run on the case: it passes when both runs ended
    ``converged`` and :func:`~signorini.crosschecking.agreement` finds them
    agreeing (no node classified apart, λ and u within its limit); its value is λ's
    relative difference.
    """
    first, partners = CROSS_CHECKED
    runs = {row["method"]: row for row in result.runs if row.get("tol") == tol}
    if first not in runs:
        return []
    checks = []
    for partner in partners:
        if partner not in runs:
            continue
        name = f"{first} cross-checked with {partner} (default form): both converged and agree"
        a, b = (result.solutions.get(label(m, tol)) for m in (first, partner))
        if a is None or b is None:
            checks.append(Check(result.case.name, name, False, None, False, "no answer to compare"))
            continue
        pair = agreement(result.problem, a, b, tol, tol)
        ok = a.status == "converged" and b.status == "converged" and pair.agree
        checks.append(Check(result.case.name, name, pair.lam_rel, pair.limit, ok,
                            f"{first} {a.status}, {partner} {b.status}; λ {pair.lam_rel:.1e}, "
                            f"u {pair.u_rel:.1e}, {pair.apart} nodes apart ({pair.weak} weak)"))
    return checks


def read_limits(path: str) -> dict[str, float]:
    """The limits a TOML file's ``[limits]`` table sets (names of :data:`LIMITS`, positive numbers).

    InputError naming the file and the fix for a missing file, bad TOML, an
    unknown name or a value that is not a positive number.
    """
    check_input_file(path, "limits file", "give a TOML file with a [limits] table")  # FIFO too
    try:
        with open(path, "rb") as handle:
            data = tomllib.load(handle)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise InputError(f"limits file {path!r} cannot be read as TOML ({exc}): fix it") from None
    stray = sorted(set(data) - {"limits"})
    if stray or not isinstance(data.get("limits"), dict):
        raise InputError(f"limits file {path!r} must hold one [limits] table"
                         + (f", not {stray[0]!r}" if stray else "")
                         + f": e.g. [limits] lam_rel_vs_pdas = 1e-5")
    given = data["limits"]
    for key, value in given.items():
        if key not in LIMITS:
            raise InputError(f"limits file {path!r}: unknown limit {key!r}: one of "
                             f"{', '.join(LIMITS)}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not (math.isfinite(value) and value > 0):
            raise InputError(f"limits file {path!r}: {key} = {value!r} must be a positive number, "
                             f"e.g. {key} = {LIMITS[key]:g}")
    return {key: float(value) for key, value in given.items()}
