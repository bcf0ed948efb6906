"""The default tolerance and iteration limit of every method, in one table, each with its reason.

A method asked for no ``tol`` runs at its row's ``tol`` and its answer is held to it;
asked for no ``max_iter``, it stops after its row's ``max_iter`` steps. A row is found by
the method's name, else by its family (:func:`defaults_of`). ``tol`` is the relative KKT
residual the certificate accepts (:mod:`signorini.certification.kkt`); None leaves a QP backend at its
own settings, its answer then held to :data:`DEFAULT_TOL`.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["DEFAULT_TOL", "EXACT_TOL", "MIN_TOL", "Defaults", "TABLE", "defaults_of", "resolved"]

#: the package's default relative KKT tolerance: what :func:`signorini.crosscheck` asks every
#: method for, what a user's method is handed when nobody names one, and what an answer is
#: held to when neither the caller nor its method names one (a QP backend at its own settings)
DEFAULT_TOL = 1e-8
#: what an exact method (its answer exact up to round-off once its active set is found) is held
#: to: one digit tighter than an iterative method is asked for
EXACT_TOL = 1e-9

#: relative KKT residuals cannot be certified below a few hundred times double precision's ε:
#: the smallest tol a method may be asked for
MIN_TOL = 1e-14


@dataclass(frozen=True)
class Defaults:
    """A method's default ``tol`` and ``max_iter`` (None: its backend's own), and why."""

    tol: float | None
    max_iter: int | None
    reason: str


#: one row per method, or per family where its methods share one
TABLE: dict[str, Defaults] = {
    "pdas": Defaults(EXACT_TOL, 100, "exact once its active set repeats, a few Newton steps; "
                                     "100 means a cycle or a degenerate set"),
    "nested": Defaults(EXACT_TOL, 100, "exact on the predicted zone; its fallback is pdas's"),
    "condensed": Defaults(EXACT_TOL, 200, "an exact dense LCP, a few active-set steps"),
    "pdas-amg": Defaults(EXACT_TOL, 50, "Newton steps on the active set with CG solves driven "
                                        "below tol; a predicted set needs a few"),
    "auto": Defaults(EXACT_TOL, None, "picks an exact method, which has its own limit"),
    "dual": Defaults(DEFAULT_TOL, 50_000, "projected gradient on the dual converges linearly, "
                                          "slowly when W is ill-conditioned: 1e-8 in its budget"),
    "petsc-vi": Defaults(EXACT_TOL, 200, "semismooth Newton (SNES-VI): exact once its active "
                                         "set settles"),
    "petsc": Defaults(EXACT_TOL, 2000, "bound-constrained TAO solvers: many cheap steps, each "
                                       "stopped below tol by PETSc's own test"),
    "qp": Defaults(None, None, "the backend's own settings (what a user of it gets); its "
                               "answer is held to DEFAULT_TOL"),
    "cvxpy": Defaults(None, None, "the chosen solver's own settings; held to DEFAULT_TOL"),
    "user": Defaults(DEFAULT_TOL, 1000, "the package's default tolerance, and a limit a user's "
                                        "method may read or ignore"),
}


def defaults_of(name: str, family: str) -> Defaults:
    """The row of the method ``name`` (of ``family``): its own, else its family's."""
    return TABLE.get(name) or TABLE.get(family) or TABLE["user"]


def resolved(name: str, family: str, tol: float | None,
             max_iter: int | None) -> tuple[float | None, int | None]:
    """``(tol, max_iter)`` as asked, each one not asked for taken from the method's row."""
    row = defaults_of(name, family)
    return (row.tol if tol is None else tol,
            row.max_iter if max_iter is None else int(max_iter))
