"""What a method returns: :class:`ContactSolution` (``u``, ``λ``, status, what it did)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from signorini.errors import InputError
from signorini.numerics.arrays import vector_argument
from signorini.reprs import short_repr

#: the statuses a :class:`ContactSolution` can carry
STATUSES = ("converged", "inaccurate", "max_iter", "diverged", "infeasible", "failed",
            "model_inadequate")


@dataclass(frozen=True)
class WarmStart:
    """Where a method may start, given explicitly: ``solve(problem, method, warm_start=...)``.

    ``lam`` and ``u`` are an earlier answer's contact forces and displacement
    (``pdas`` starts from both, ``pdas-amg`` from the active set of ``lam``);
    ``zone_solver`` holds a factorisation of this K around the contact
    ``zone`` (a :class:`~signorini.numerics.zone.ZoneSolver`; ``nested``
    reuses both and costs back-solves only); ``factor`` a factorisation of
    this K with an active set's dofs pinned or of its saddle-point system (load
    control's last), which ``pdas`` reuses
    when its first active set is that one. A method never reads a warm
    start from anywhere else.
    """

    lam: np.ndarray | None = None
    u: np.ndarray | None = None
    zone_solver: Any = None
    zone: Any = None
    factor: Any = None

    @classmethod
    def of(cls, earlier: Any) -> "WarmStart":
        """A warm start from an earlier answer: a WarmStart, a ContactSolution or a Result."""
        if isinstance(earlier, WarmStart):
            return earlier
        solution = getattr(earlier, "solution", earlier)
        if not isinstance(solution, ContactSolution):
            raise InputError(f"warm_start must be an earlier Result, ContactSolution or "
                             f"WarmStart, got {type(earlier).__name__}")
        return cls(lam=solution.lam, u=solution.u)

    def check_fits(self, n: int, m: int) -> "WarmStart":
        """Itself with float arrays, when its ``u`` has ``n`` finite entries and its ``lam``
        ``m``; InputError otherwise."""
        arrays = {}
        for name, value, size in (("u", self.u, n), ("lam", self.lam, m)):
            if value is None:
                continue
            arrays[name] = vector_argument(value, f"warm_start's {name}")
            if arrays[name].shape != (size,):
                raise InputError(f"warm_start: its {name} has shape {np.shape(value)} and this "
                                 f"problem needs ({size},): start from an answer of this problem "
                                 "(the same mesh and candidates), or give no warm_start")
            if not np.all(np.isfinite(arrays[name])):
                raise InputError(f"warm_start: its {name} is not finite (NaN or inf, as a failed "
                                 "run's): start from a finite answer, or give no warm_start")
        return replace(self, **arrays)


@dataclass
class ContactSolution:
    """What a solver returns: ``u`` (free dofs), ``lam`` (contact forces), status.

    ``status`` is one of :data:`STATUSES`. ``converged`` means the solver
    claims success *and* the package's KKT certificate agrees (the wrapper in
    :func:`signorini.solvers.registry.solve` enforces this). ``history`` maps a name to
    one value per iteration (``kkt``, ``primal``, ``dual``...).

    ``u`` and ``lam`` are in the units of the problem's arrays: dimensionless for
    a scene built with ``nondimensionalise=True`` (the default; multiply by
    ``problem.scales``), the user's own for a QP given as arrays; a
    :class:`signorini.result.Result` gives displacements, gaps, forces and
    pressures in the problem's physical units.
    """

    method: str
    u: np.ndarray
    lam: np.ndarray
    status: str
    message: str = ""
    iterations: int = 0
    build_time: float = 0.0
    solve_time: float = 0.0
    history: dict[str, list[float]] = field(default_factory=dict)
    extras: dict[str, Any] = field(default_factory=dict)
    #: the method's own status when the package's certificate disagreed with it ("" otherwise)
    claimed_status: str = ""
    #: a factorisation of the problem's K the method holds (a PinnedFactor, possibly with
    #: contact dofs pinned), which the certificate reuses for its duality gap and then lets go,
    #: unless ``keep_factor`` (asked for by ``signorini.solve(..., keep_factor=True)``: the
    #: first derivative of the answer then reuses it when it pins the final active set)
    factor: Any = field(default=None, repr=False, compare=False)
    keep_factor: bool = field(default=False, repr=False, compare=False)
    #: the work of every stage that ran, by stage ("method", "load_control"): active-set or
    #: load-control steps, factorisations, back-solves, CG iterations
    work: dict[str, dict[str, int]] = field(default_factory=dict)
    #: the wall time of every stage that ran, by stage ("load control", "method",
    #: "certificate"), in seconds (:func:`signorini.numerics.work.timed`)
    seconds: dict[str, float] = field(default_factory=dict)
    __repr__ = short_repr

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status {self.status!r} is not one of {STATUSES}")

    @property
    def contact_force(self) -> np.ndarray:
        return self.lam

    @property
    def own_status(self) -> str:
        """What the method itself said: its claim when the certificate overruled it."""
        return self.claimed_status or self.status

    @property
    def success(self) -> bool:
        return self.status == "converged"

    @classmethod
    def failure(cls, method: str, problem: Any, status: str, message: str,
                **kwargs: Any) -> "ContactSolution":
        """A solution carrying no answer (NaN vectors) and a reason."""
        return cls(method=method, u=np.full(problem.n, np.nan), lam=np.full(problem.m, np.nan),
                   status=status, message=message, **kwargs)


__all__ = ["WarmStart", "ContactSolution", "STATUSES"]
