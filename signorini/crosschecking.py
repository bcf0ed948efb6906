"""Cross-checking methods against each other: the paper's Uzawa, QP backends, the exact answer.

``crosscheck(problem, methods)`` solves one problem with every method at one relative KKT
tolerance and compares every pair of answers (:func:`signorini.certification.comparison.compare`):
λ and u by their relative ∞-norm distance (``lam_rel``, ``u_rel``), and the candidates
classified ``apart`` (active in one answer, inactive in the other). A node is **weakly active**
in an answer when its scaled force and gap are both at most ``max(kkt.WEAK_TOL, tol_a, tol_b)``:
it touches with (next to) no force, no residual within the tolerance can say on which side it
belongs, and it is counted apart (``weak``).

A pair is **judged** when both methods *say* ``converged`` (their own claim, backed by the
certificate or not: a claim of success is what a cross-check tests), and it **disagrees** when
a node is classified apart or λ or u differ by more than ``AGREE_FACTOR × max(tol_a, tol_b)``.
The factor: the certificate bounds residuals, not errors, and W = N K⁻¹ Nᵀ turns residuals
within tol into λ errors of up to 1.6e3 × tol in the formulation runs (docs/crosscheck.md);
10⁴ leaves room for finer meshes and still catches, at tol 1e-8, a λ off by 1e-4. The check
**passes** when every method converged and no judged pair disagrees (``allow`` lets known-weak
methods through). The methods run one after another in this process (a problem from
:meth:`ContactProblem.from_qp` cannot be rebuilt in a worker).
"""

from __future__ import annotations

import itertools
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from signorini.api import SCHEMA_VERSION, Result, record_units, solve
from signorini import scenes  # loaded at first use: a QP given as arrays needs no scene
from signorini.crosscheck_tables import render, render_candidates, render_markdown
from signorini.errors import BackendNotInstalled, InputError
from signorini.certification.comparison import compare
from signorini.certification.kkt import ACTIVE, INACTIVE, WEAK_TOL, classify
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.references.catalogue import reference_metrics, reference_of
from signorini.solvers.base import check_tol
from signorini.solvers.options import DEFAULT_TOL
from signorini.solvers.registry import REGISTRY, get_method, given

#: the methods compared when none are named: the paper's, the two named QP backends,
#: the modelling layer and the exact reference
DEFAULT_METHODS = ("uzawa", "qp-osqp", "qp-clarabel", "cvxpy", "pdas")
#: two converged answers agree when λ and u differ by at most this × the larger tolerance
AGREE_FACTOR = 1e4
#: a row's status when the method refused the problem or its backend is missing
REFUSED, NOT_INSTALLED = "refused", "not installed"


@dataclass
class MethodRun:
    """One method's answer: what it said, what the certificate says, and Hertz's errors.

    ``form`` is the QP formulation a QP method ran; ``polished`` is True when
    the polished answer is returned, False when polish left the backend's own,
    None when there was no polish. ``reference`` holds the errors against the
    problem's analytic reference (``p0_rel``, ``a_rel``, ``pressure_l2_rel`` for
    Hertz), empty when it has none. ``lam_ref`` (λ's relative distance), ``active``
    (candidates in contact) and ``apart_ref`` (nodes classified apart) set the answer
    against the reference method's: pdas when it is compared, else the first exact
    method that converged (NaN and -1 when there is none); ``polished_lam_ref`` and
    ``polished_status`` are those of the polished answer when polish was asked
    for (None otherwise); ``allowed`` says the method was let through.
    """

    method: str
    tol: float
    status: str
    claimed_status: str
    message: str
    iterations: int = 0
    time_s: float = float("nan")
    form: str = ""
    polished: bool | None = None
    kkt: dict[str, float] = field(default_factory=dict)
    kkt_worst: float = float("nan")
    kkt_worst_name: str = ""
    reference: dict[str, float] = field(default_factory=dict)
    lam_ref: float = float("nan")
    active: int = -1
    apart_ref: int = -1
    polished_lam_ref: float | None = None
    polished_status: str | None = None
    allowed: bool = False

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class Pair:
    """Two methods' answers compared (see the module's docstring for every field)."""

    first: str
    second: str
    lam_rel: float
    u_rel: float
    apart: int
    weak: int
    weak_tol: float
    limit: float
    judged: bool

    @property
    def agree(self) -> bool:
        """Within ``limit`` in λ and u, and no node classified apart."""
        return bool(self.lam_rel <= self.limit and self.u_rel <= self.limit and self.apart == 0)

    @property
    def verdict(self) -> str:
        """``agree`` or ``DISAGREE`` for a judged pair; otherwise ``not judged``."""
        if not self.judged:
            return "not judged"
        return "agree" if self.agree else "DISAGREE"

    def as_dict(self) -> dict[str, Any]:
        return {**asdict(self), "agree": self.agree, "verdict": self.verdict}


def agreement(problem: ContactProblem, first: ContactSolution, second: ContactSolution,
              tol_first: float, tol_second: float) -> Pair:
    """Compare two answers of ``problem`` (solved at ``tol_first`` and ``tol_second``).

    The one definition of agreement: the cross-check and the validation suite both use it.
    """
    loose = max(tol_first, tol_second)
    weak_tol = max(WEAK_TOL, loose)
    found = compare(problem, first, second, weak_tol=weak_tol)
    judged = first.own_status == "converged" and second.own_status == "converged"
    return Pair(first.method, second.method, found.lam_rel, found.u_rel, found.misclassified,
                found.weak, weak_tol, AGREE_FACTOR * loose, judged)


@dataclass
class CrossCheck:
    """Every method's run and every pair's comparison on one problem."""

    problem: ContactProblem
    tol: float
    runs: list[MethodRun]
    pairs: list[Pair]
    results: dict[str, Result] = field(default_factory=dict, repr=False)
    allowed: tuple[str, ...] = ()
    reference_method: str = ""
    polish: bool = False

    @property
    def disagreements(self) -> list[Pair]:
        """Pairs of methods that both said ``converged`` and disagree."""
        return [pair for pair in self.pairs if pair.verdict == "DISAGREE"]

    @property
    def failures(self) -> list[str]:
        """What fails the check, one line each: a method that did not converge (with its message
        when it failed: an exception and its line), a pair that disagrees (``allowed`` left out)."""
        said = [f"{run.method} {run.status}" + (f" ({run.message})" if run.status == "failed"
                                                  and run.message else "")
                for run in self.runs if run.status != "converged" and run.method not in self.allowed]
        said += [f"{pair.first} ~ {pair.second} disagree" for pair in self.disagreements
                 if pair.first not in self.allowed and pair.second not in self.allowed]
        return said

    @property
    def passed(self) -> bool:
        """Every method converged and no judged pair disagrees (``allowed`` methods aside)."""
        return not self.failures

    def to_dict(self) -> dict[str, Any]:
        """The record ``signorini crosscheck --json`` writes."""
        problem = self.problem
        return {"schema_version": SCHEMA_VERSION, "units": record_units(problem),
                "scene": problem.name, "params": problem.model.params, "dofs": problem.n,
                "contact_candidates": problem.m, "tol": self.tol,
                "reference": problem.model.reference_name, "agree_factor": AGREE_FACTOR,
                "passed": self.passed, "failures": self.failures, "allowed": list(self.allowed),
                "reference_method": self.reference_method, "polish": self.polish,
                "methods": [run.as_dict() for run in self.runs],
                "pairs": [pair.as_dict() for pair in self.pairs],
                "candidates": candidate_rows(problem, self.results, self.tol)}

    def summary(self, verbose: bool = False) -> str:
        """The printed tables (what ``signorini crosscheck`` shows; ``verbose``: with ``-v``,
        also the table per candidate)."""
        record = self.to_dict()
        return render(record) + ("\n\n" + render_candidates(record) if verbose else "")

    def markdown(self) -> str:
        """The same tables in Markdown (``signorini crosscheck --md``)."""
        return render_markdown(self.to_dict())


def _reference_errors(result: Result) -> dict[str, float]:
    reference = reference_of(result.problem)
    if reference is None or not result.finite:
        return {}
    metrics = reference_metrics(result.problem, result.solution)
    keys = reference.convergence or tuple(k for k in ("pressure_max_rel",) if k in metrics)
    return {key: float(metrics[key]) for key in keys if key in metrics}


def _run_of(result: Result, tol: float) -> MethodRun:
    solution = result.solution
    cert = result.certificate
    worst_name, worst = cert.worst()
    polish = solution.extras.get("polish")
    return MethodRun(result.method, tol, solution.status, solution.own_status, solution.message,
                     result.iterations, float(solution.seconds.get("method", float("nan"))),
                     str(solution.extras.get("form", "")),
                     None if polish is None else bool(polish.get("kept")), cert.as_dict(),
                     float(worst), worst_name, _reference_errors(result))


def crosscheck(problem: ContactProblem | str, methods: list[str] | tuple[str, ...] | None = None,
               *, tol: float | None = DEFAULT_TOL, params: dict[str, Any] | None = None,
               options: dict[str, dict[str, Any]] | None = None,
               allow: list[str] | tuple[str, ...] = (), polish: bool = False) -> CrossCheck:
    """Solve ``problem`` with every method; for every pair ``‖λ_a − λ_b‖∞ / max(‖λ_a‖∞, ‖λ_b‖∞)``,
    the same for u, and the nodes classified apart (see the module's docstring).

    Parameters
    ----------
    problem : a :class:`ContactProblem`, or a scene name or ``.toml`` file built with ``params``.
    methods : method names (default :data:`DEFAULT_METHODS`); for your own, ``module:function``
        or the function itself (known by its name).
    tol : the relative KKT tolerance every method is asked for (default
        :data:`signorini.DEFAULT_TOL`; ``None`` leaves each method its own default).
    options : per-method options, ``{"qp-cvxpy": {"solver": "OSQP"}}``; a method
        with the option ``polish`` gets ``polish=False`` unless given here.
    allow : methods whose failure or disagreement does not fail the check (known-weak).
    polish : also polish each QP method's answer (a second run), shown as an extra column.

    Returns
    -------
    CrossCheck
        ``runs`` (status, claim, certificate, distance to the reference answer,
        Hertz's errors), ``pairs`` (λ, u, nodes apart, verdict), ``passed``
        (every method converged and no judged pair disagrees), ``failures``.

    Raises
    ------
    InputError
        An unknown method, a method named twice, options for a method not
        compared, a method allowed but not compared, a bad tolerance: before
        anything is solved.
    """
    if isinstance(methods, str):
        raise InputError(f"methods must be a list of names, got the string {methods!r}: "
                         f"write methods=[{methods!r}, 'pdas']")
    chosen = [get_method(name) for name in (DEFAULT_METHODS if methods is None else methods)]
    names = [method.name for method in chosen]  # an unknown one fails here, before work
    if len(names) < 2:
        raise InputError(f"a cross-check compares at least two methods, got {names}: "
                         "name two or more (--method uzawa --method pdas)")
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise InputError(f"method {twice[0]!r} is named twice: name each method once")
    options = dict(options or {})
    stray = sorted(set(options) - set(names))
    if stray:
        raise InputError(f"options for {stray[0]!r}, which is not among the methods "
                         f"({', '.join(names)}): add it with --method {stray[0]}")
    if isinstance(allow, str):
        allow = [allow]
    strange = sorted(set(allow) - set(names))
    if strange:
        raise InputError(f"allow names {strange[0]!r}, which is not among the methods "
                         f"({', '.join(names)}): allow only a method that is compared")
    if not isinstance(polish, (bool, np.bool_)):
        raise InputError(f"polish={polish!r} must be True or False")
    tol = check_tol(tol)
    if isinstance(problem, str):
        problem = scenes.build_problem(problem, params=params)
    elif params:
        raise InputError("params= builds a scene by name: give crosscheck('hertz-cylinder', "
                         "params=...) or build the problem with those parameters first")
    elif not isinstance(problem, ContactProblem):
        raise InputError(f"problem must be a ContactProblem or a scene name, got "
                         f"{type(problem).__name__}")
    with given({method.name: method for method in chosen if method.name not in REGISTRY}):
        return _crosscheck(problem, names, tol, options, tuple(allow), bool(polish))


def _crosscheck(problem: ContactProblem, names: list[str], tol: float | None,
                options: dict[str, dict[str, Any]], allow: tuple[str, ...],
                polish: bool) -> CrossCheck:
    """:func:`crosscheck` once its arguments are checked, every method known by its name."""
    judged_tol = tol if tol is not None else DEFAULT_TOL
    runs: list[MethodRun] = []
    results: dict[str, Result] = {}
    for name in names:
        try:
            result = solve(problem, name, tol=tol, **_raw(name, options.get(name, {})))
        except BackendNotInstalled as exc:
            runs.append(MethodRun(name, judged_tol, NOT_INSTALLED, NOT_INSTALLED, str(exc)))
            continue
        except InputError as exc:  # e.g. a dense backend refusing a large problem
            if name in options:
                raise  # the caller's own options are wrong: say so, as solve would
            runs.append(MethodRun(name, judged_tol, REFUSED, REFUSED, str(exc)))
            continue
        results[name] = result
        runs.append(_run_of(result, judged_tol))
    tol_of = {run.method: run.tol for run in runs}
    pairs = [agreement(problem, results[a].solution, results[b].solution, tol_of[a], tol_of[b])
             for a, b in itertools.combinations(names, 2) if a in results and b in results]
    reference = _reference_method(names, results)
    for run in runs:
        run.allowed = run.method in allow
        if run.method not in results:
            continue
        run.active = int(np.sum(classify(problem, results[run.method].solution) == ACTIVE))
        if reference:
            run.lam_ref, run.apart_ref = _against(problem, results[reference], results[run.method])
        if polish and "polish" in get_method(run.method).options:
            polished = solve(problem, run.method, tol=tol,
                             **{**options.get(run.method, {}), "polish": True})
            run.polished_status = polished.status
            if reference:
                run.polished_lam_ref = _against(problem, results[reference], polished)[0]
    return CrossCheck(problem, judged_tol, runs, pairs, results, allow, reference, polish)


def _raw(name: str, options: dict[str, Any]) -> dict[str, Any]:
    """A method's options for its own answer: ``polish=False`` unless the caller set it."""
    if "polish" in get_method(name).options and "polish" not in options:
        return {**options, "polish": False}
    return options


def candidate_rows(problem: ContactProblem, results: dict[str, Result],
                   tol: float) -> list[dict[str, Any]]:
    """Per candidate: its index, point, and each method's gap (``d − Nu``: > 0 apart, < 0
    penetrating), λ and classification (:func:`signorini.certification.kkt.classify`, weak below
    ``max(WEAK_TOL, tol)``; ``penetrating`` an inactive one inside the obstacle), in the user's units."""
    labels = {name: classify(problem, result.solution, max(WEAK_TOL, tol))
              for name, result in results.items()}
    points = problem.contact_points * problem.scales.length
    return [{"index": i, "point": None if np.isnan(points[i]).any() else points[i].tolist(),
             "gap": {name: float(result.gap[i]) for name, result in results.items()},
             "lam": {name: float(result.force[i]) for name, result in results.items()},
             "class": {name: "penetrating" if labels[name][i] == INACTIVE and result.gap[i] < 0
                       else str(labels[name][i]) for name, result in results.items()}}
            for i in range(problem.m)]


def _reference_method(names: list[str], results: dict[str, Result]) -> str:
    """pdas when it converged, else the first exact method that did ("" for none)."""
    done = [name for name in names if name in results and results[name].converged]
    exact = [name for name in done if get_method(name).exact]
    return "pdas" if "pdas" in done else (exact[0] if exact else "")


def _against(problem: ContactProblem, reference: Result, result: Result) -> tuple[float, int]:
    """λ's relative distance to the reference answer and the nodes classified apart."""
    found = compare(problem, reference.solution, result.solution)
    return found.lam_rel, found.misclassified


__all__ = ["AGREE_FACTOR", "DEFAULT_METHODS", "CrossCheck", "MethodRun", "Pair",
           "agreement", "candidate_rows", "crosscheck", "render", "render_markdown"]
