"""What a method returns: :class:`ContactSolution` (``u``, ``λ``, status, what it did)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: the statuses a :class:`ContactSolution` can carry
STATUSES = ("converged", "inaccurate", "max_iter", "diverged", "infeasible", "failed",
            "model_inadequate")


@dataclass
class ContactSolution:
    """What a solver returns: ``u`` (free dofs), ``lam`` (contact forces), status.

    ``status`` is one of :data:`STATUSES`. ``converged`` means the solver
    claims success *and* the package's KKT certificate agrees (the wrapper in
    :func:`signorini.solvers.registry.solve` enforces this). ``history`` maps a name to
    one value per iteration (``kkt``, ``primal``, ``dual``...).

    ``u`` and ``lam`` are in the problem's units, which are dimensionless for
    a scene built with ``nondimensionalise=True`` (the default): multiply by
    ``problem.scales`` or read :class:`signorini.api.Result`, which gives
    displacements, gaps, forces and pressures in the scene's own units.
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
    #: contact dofs pinned), which the certificate reuses for its duality gap and then lets go
    factor: Any = field(default=None, repr=False, compare=False)
    #: the problem this answer solves when the method matched a pending target load itself
    #: (the given problem pushed to the load: ``problem.pushed(s)``); None: the problem given
    problem: Any = field(default=None, repr=False, compare=False)

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
