"""A run of a study and its row: the :class:`Task` a study sends, the :class:`Row` it gets back.

The columns, the measurements a task may ask for (:data:`MEASURES`) and the
verdicts on a row (:func:`verdict`) are defined here; the runner
(:mod:`signorini.studies.runner`) fills the rows.
"""

from __future__ import annotations

import json
import logging
from dataclasses import asdict, dataclass, field
from typing import Any, TypedDict

from signorini.solvers.options import DEFAULT_TOL
from signorini.studies.problems import REFERENCE_TOL, reference_policy

log = logging.getLogger(__name__)

#: the tolerance of a task unless it says otherwise: the package's default
ATLAS_TOL = DEFAULT_TOL
#: seconds a run may take (problem assembly and the reference included) before it is stopped
DEFAULT_TIME_LIMIT = 30.0
#: the "method" of a task that only builds (and diagnoses) its problem
BUILD_ONLY = "(build)"
#: the "method" of a task that cross-checks its problem (:func:`signorini.crosscheck`) by the
#: methods ``options["methods"]``, each with its ``options["options"][method]`` (crosscheck)
CROSSCHECK = "(crosscheck)"
#: the "method" of a task that runs ``python options["argv"]…`` as a process of its own, timed
#: whole (:func:`signorini.studies.measures.whole_process`; ``options["record"]``,
#: ``options["ranks"]``); its problem is not built (process)
COMMAND = "(command)"
#: what a task may ask to measure besides the row every task gets, and the columns it fills
MEASURES = {
    "diagnosis": "what signorini.certification.diagnosis finds in the problem (diagnosis)",
    "bound": "Uzawa's effective step bound at the exact active set (bound_at_solution)",
    "patch": "λ against the force-controlled patch solution (patch_lam_rel)",
    "profile": "the contact pressure, with the reference's a and p₀ where it draws one (profile)",
    "kkt": "every relative residual of the certificate (kkt)",
    "times": "build, solve and the method's own time, not the certificate's (build_s, solve_s, "
             "method_s)",
    "vs_reference": "signorini.certification.comparison.compare with the exact answer (vs_reference)",
    "reference": "the errors against the analytic reference the problem declares (reference)",
    "estimate": "the a posteriori estimates, energy norm and contact pressure, η and its parts, "
                "η without the contact term, and its time (estimate)",
    "finer": "the energy-norm error against the same scene at each refine of "
             "reference['finer']['levels'], solved by its 'method' at its 'tol' (finer)",
    "lam": "the contact forces (lam)",
    "answer": "the answer itself: u, λ, status and message (answer)",
    "exact": "the exact answer the task is held to, converged or not (exact)",
    "mesh": "the spacing of the contact candidates and the assembly time (h, assemble_s)",
    "factorisation": "one factorisation + solve of K in this process before the method, and the "
                     "method's time over it (factor_s, ratio_to_factor)",
    "matrix": "the nonzeros of K (nonzeros)",
    "forward_error": "λ's true error against the exact answer beside the certificate's estimate "
                     "of it, its floor and back-solves (forward_error)",
    "factor_memory": "PARDISO's memory estimate for K against the resident memory its "
                     "factorisation took in the worker: a fresh task's own (factor_memory)",
}


Row = TypedDict("Row", {
    # the task: a study's coordinates (axis, case, value; the suite's label, the benchmark's size,
    # tolerance and ranks), the method, the problem and what it is
    "axis": str, "case": str, "value": float | str, "label": str, "size": str, "tolerance": str,
    "ranks": int, "method": str, "tol": float | None, "expect": str, "options": str,
    "problem": str, "scene": str, "dofs": int, "candidates": int, "h": float, "nonzeros": int,
    "assemble_s": float, "diagnosis": str,
    # what the method said, and the times
    "status": str, "claimed_status": str, "wrapper": str, "message": str, "iterations": int,
    "time_s": float, "build_s": float, "solve_s": float, "method_s": float, "factor_s": float,
    "ratio_to_factor": float,
    # the certificate: the worst relative residual and its name, accepted or not, every residual
    "kkt_worst": float, "kkt_name": str, "cert_ok": bool, "kkt": dict[str, float],
    # the exact answer and the distance from it
    "exact": dict[str, Any], "lam_rel": float, "u_rel": float, "misclassified": int,
    "weak": int, "misclassified_strict": int, "weak_penetrating": int, "exact_ok": bool,
    "near_exact": bool, "vs_reference": dict[str, float], "patch_lam_rel": float,
    # theory: Hertz's cylinder (the exact answer's prefixed ref_) and the declared reference
    "a_rel": float, "p0_rel": float, "pressure_l2_rel": float, "ref_a_rel": float,
    "ref_p0_rel": float, "ref_pressure_l2_rel": float, "reference": dict[str, float],
    "estimate": dict[str, float], "forward_error": dict[str, float],
    "factor_memory": dict[str, float], "crosscheck": dict[str, Any], "finer": dict[str, Any],
    "process": dict[str, Any],
    "profile": dict[str, Any], "lam": list[float], "answer": dict[str, Any],
    # what a method reports about itself
    "rho_over_bound": float, "lambda_max": float, "bound_at_solution": float,
    # verdicts
    "claim_correct": bool, "wrapper_right": bool, "conservative": bool, "outcome": str,
}, total=False)
Row.__doc__ = """One run of any study: where it ran, what the method said, what the package measured.

The atlas writes every column it knows; the suite, the benchmark and the
convergence studies write the columns of their own tables. The benchmark's
table writes the method's label (``petsc-vi n=2``) as ``method``. What each
optional measurement fills is listed in :data:`MEASURES`.
"""


@dataclass(frozen=True)
class Task:
    """One run: a method at a tolerance on a problem, and what to compare it with.

    ``axis``, ``case`` and ``value`` place the run in its study. ``expect``
    is ``"solve"`` when a right answer exists, ``"refuse"`` when the right
    outcome is an error or a non-converged status (infeasible input).
    ``answer`` says whether answers are compared by ``"lambda"`` or, where λ
    is not unique, by ``"displacement"``. ``reference`` names the policy of
    the exact answer. ``measure`` names extra measurements (:data:`MEASURES`).
    A ``fresh`` task runs in a process of its own, the method before
    anything else touches the problem (the exact answer comes after it), so
    that its time is that of a cold start; ``ranks`` > 1 runs it under ``mpirun``.
    """

    axis: str
    case: str
    value: float | str
    problem: dict[str, Any]
    method: str
    tol: float | None = ATLAS_TOL
    options: dict[str, Any] = field(default_factory=dict)
    max_iter: int | None = None
    reference: dict[str, Any] = field(default_factory=lambda: {"kind": "pdas"})
    expect: str = "solve"
    answer: str = "lambda"
    measure: tuple[str, ...] = ()
    fresh: bool = False
    ranks: int = 1

    def __post_init__(self) -> None:
        unknown = [m for m in self.measure if m not in MEASURES]
        if unknown:
            raise ValueError(f"unknown measure {unknown[0]!r}: one of {', '.join(MEASURES)}")
        reference_policy(self.reference)  # an unknown policy fails here, not in a worker

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @property
    def is_policy_run(self) -> bool:
        """This run is the one its reference policy would make: its answer can be the reference."""
        return (reference_policy(self.reference).method == self.method and not self.options
                and self.max_iter is None and self.tol == self.reference.get("tol", REFERENCE_TOL))


def task_row(task: Task) -> Row:
    """The columns a row takes from its task."""
    return Row(axis=task.axis, case=task.case, value=task.value, method=task.method, tol=task.tol,
               expect=task.expect,
               options=json.dumps(task.options, sort_keys=True) if task.options else "",
               problem=json.dumps(task.problem, sort_keys=True))


def verdict(row: Row, task: Task) -> Row:
    """Whether the method's claim and the package's status were right; the run's outcome.

    ``exact_ok``: the answer agrees with the exact one (unknown without one: the
    certificate stands in). ``claim_correct``: the method did not claim
    success, or its answer passes the certificate and agrees. ``wrapper_right``:
    ``converged`` only for an answer that agrees, and granted whenever the
    method claimed success and the answer passes and agrees. ``conservative``:
    the certificate turned down a claim whose answer does agree.
    """
    status, claimed = row.get("status"), row.get("claimed_status")
    exact_ok = row.get("exact_ok")
    if exact_ok is None:
        exact_ok = row.get("cert_ok")
    exact_ok = bool(exact_ok) and task.expect == "solve"
    near_exact = bool(row.get("near_exact", exact_ok)) and exact_ok
    cert_ok = bool(row.get("cert_ok"))
    claimed_success = claimed == "converged"
    row["claim_correct"] = (not claimed_success) or (cert_ok and exact_ok)
    row["conservative"] = claimed_success and not cert_ok and near_exact
    if status in ("input-error", "refused", "built", "checked", "ran", "timeout", "crashed"):
        row["wrapper_right"] = True  # a clear error, or a method that never answered
    elif status == "raised":
        row["wrapper_right"] = False
    elif status == "infeasible" and task.expect == "solve":
        row["wrapper_right"] = False  # "infeasible" for a problem that has a solution
    elif status == "converged":
        row["wrapper_right"] = exact_ok
    else:
        row["wrapper_right"] = not (claimed_success and cert_ok and exact_ok)
    if task.method == COMMAND:
        row["outcome"] = "right" if row.get("process", {}).get("returncode") == 0 else "wrong"
    elif task.method == CROSSCHECK:
        row["outcome"] = "right" if row.get("crosscheck", {}).get("passed") else "wrong"
    elif task.method == BUILD_ONLY:
        flagged = status == "input-error" or bool(row.get("diagnosis"))
        row["outcome"] = "right" if flagged == (task.expect == "refuse") else "wrong"
    elif task.expect == "refuse":
        row["outcome"] = "right" if status not in ("converged", "raised") else "wrong"
    elif status == "converged":
        row["outcome"] = "right" if exact_ok else "wrong"
    elif status == "raised" or not row["wrapper_right"]:
        row["outcome"] = "wrong"
    elif row["conservative"]:
        row["outcome"] = "conservative"  # a right answer the certificate did not accept
    elif claimed_success:
        row["outcome"] = "caught"  # the method claimed success; the certificate said no
    else:
        row["outcome"] = "failed"
    return row


def failed_row(task: Task, exc: Exception) -> Row:
    """The row of a task on which the runner itself failed (a bug of the runner, not of a method)."""
    log.exception("the runner failed on %s / %s", task.case, task.method)
    return verdict(Row(**task_row(task), status="crashed", claimed_status="",
                       wrapper="runner error",
                       message=f"runner error {type(exc).__name__}: {exc}"), task)


__all__ = ["Task", "task_row", "verdict", "failed_row", "ATLAS_TOL", "DEFAULT_TIME_LIMIT",
           "BUILD_ONLY", "CROSSCHECK", "COMMAND", "MEASURES", "Row"]
