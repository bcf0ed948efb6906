"""Run an exported test set through qpbenchmark and judge every answer by the certified one.

qpbenchmark's own loop (``qpbenchmark.run``) keeps only residuals; this one makes the same
calls (``time_solve_problem`` with the test set's settings, ``Results.update``, the same
report) and also keeps what each solver returned, to compare it with the stored answer
``(x*, z*)`` and to certify it with :func:`signorini.certificate` on the same QP.

A run is **close** when the solver says it found a solution and both
``‖x − x*‖∞ / ‖x*‖∞`` and ``‖z − z*‖∞ / ‖z*‖∞`` are at most :data:`ACCURACY` of its settings;
it is **valid** for qpbenchmark when it found one with every residual under the settings'
(absolute) tolerances. Their rates mirror qpbenchmark's: the *success rate* counts valid
(or close) runs, the *correct rate* the runs whose claim of success was honest (found ==
valid, or found == close).
"""

from __future__ import annotations

import logging
import os
from dataclasses import asdict, dataclass
from typing import Iterable

import numpy as np

from signorini.api import certificate
from signorini.problem.contact import ContactProblem

__all__ = ["ACCURACY", "DENSE_SCRIPT", "SCRIPT", "Judged", "judge", "run"]

log = logging.getLogger(__name__)

#: the relative distance to the certified answer (x and z, ∞-norm) that counts as close, per
#: qpbenchmark settings
ACCURACY = {"default": 1e-3, "low_accuracy": 1e-3, "mid_accuracy": 1e-6, "high_accuracy": 1e-6}
#: the test set's scripts, as ``signorini export qpbenchmark`` writes them: the sparse set and
#: its dense subset
SCRIPT, DENSE_SCRIPT = "signorini_contact.py", "signorini_contact_dense.py"


@dataclass
class Judged:
    """One solver's run on one problem: qpbenchmark's verdict and the certified answer's."""

    problem: str
    solver: str
    settings: str
    runtime: float
    found: bool
    primal_residual: float
    dual_residual: float
    duality_gap: float
    #: qpbenchmark's verdict: found, and every residual under the settings' tolerances
    valid: bool
    #: ‖x − x*‖∞ / ‖x*‖∞ and ‖z − z*‖∞ / ‖z*‖∞ (inf when nothing was found)
    x_error: float
    z_error: float
    #: found, and x and z within ACCURACY[settings] of the certified answer
    close: bool
    #: the package's certificate of the answer: its worst relative residual and which
    certificate: float
    certificate_worst: str

    def row(self) -> dict:
        return asdict(self)


def _relative(a, b: np.ndarray) -> float:
    if a is None or np.shape(a) != b.shape or not np.all(np.isfinite(a)):
        return float("inf")
    return float(np.max(np.abs(a - b), initial=0.0) / max(np.max(np.abs(b), initial=0.0), 1e-300))


def judge(qp, solution, reference: tuple, tolerance, settings: str, runtime: float,
          solver: str, name: str) -> Judged:
    """Judge one qpsolvers ``solution`` of the ContactProblem ``qp`` against ``reference``."""
    x_ref, z_ref, _ = reference
    found = bool(solution.found)
    residuals = (solution.primal_residual(), solution.dual_residual(), solution.duality_gap())
    valid = found and residuals[0] < tolerance.primal and residuals[1] < tolerance.dual \
        and residuals[2] < tolerance.gap
    x_error = _relative(solution.x, x_ref) if found else float("inf")
    z_error = _relative(solution.z, z_ref) if found else float("inf")
    close = found and max(x_error, z_error) <= ACCURACY[settings]
    worst, value = "not found", float("inf")
    if found and np.isfinite(x_error) and np.isfinite(z_error):
        worst, value = certificate(qp, u=solution.x, force=solution.z).worst()
    return Judged(name, solver, settings, float(runtime), found, *map(float, residuals), bool(valid),
                  x_error, z_error, bool(close), float(value), worst)


def run(directory: str, *, solvers: Iterable[str] | None = None,
        settings: Iterable[str] = ("default", "high_accuracy"), author: str = "signorini",
        script: str = SCRIPT) -> list[Judged]:
    """Every (problem, solver, settings) of the test set in ``directory``, judged twice.

    ``script`` is the test set (:data:`SCRIPT` or :data:`DENSE_SCRIPT`); ``solvers`` default to
    every one it takes; the settings not named are left out of the run and of the report.
    Writes qpbenchmark's results (``results/qpbenchmark_results*.csv``) and report
    (``results/<script>.md``) as ``python <script> run`` would, and returns the judged runs
    in the test set's order (solvers sorted).
    """
    from qpbenchmark import Report, Results  # optional: pip install qpbenchmark
    from qpbenchmark.benchmark import load_test_set
    from qpbenchmark.utils import time_solve_problem

    path = os.path.abspath(os.path.join(directory, script))
    test_set = load_test_set(path)
    settings = list(settings)
    for name in set(test_set.solver_settings) - set(settings):
        del test_set.solver_settings[name], test_set.tolerances[name]
    chosen = sorted(test_set.solvers if solvers is None else set(solvers) & test_set.solvers)
    stem = os.path.splitext(script)[0]
    results_dir = os.path.join(os.path.dirname(path), "results")
    results = Results(os.path.join(results_dir, "qpbenchmark_results"
                                   + ("_dense" if script == DENSE_SCRIPT else "") + ".csv"), test_set)
    judged = []
    for problem in test_set:
        qp = ContactProblem.from_qp(problem.P, -problem.q, problem.G, problem.h,
                                              name=problem.name)
        reference = test_set.reference(problem.name)
        for solver in chosen:
            for name in settings:
                log.info("%s: %s at %s", problem.name, solver, name)
                kwargs = test_set.solver_settings[name][solver]
                solution, runtime = time_solve_problem(problem, solver, **kwargs)
                results.update(problem, solver, name, solution, runtime)
                judged.append(judge(qp, solution, reference, test_set.tolerances[name], name,
                                    runtime, solver, problem.name))
        results.write()
    Report(author, results).write(os.path.join(results_dir, f"{stem}.md"))
    return judged
