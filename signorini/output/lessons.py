"""The explorer's lessons as plain functions: each takes what a slider sets and re-solves.

Four lessons, each one call that solves in the package and returns numbers and the data
its figure draws (:mod:`signorini.output.lesson_figures` draws them):

- :func:`uzawa_lesson`: Uzawa's iterates on the bogie's dual function
  ``D(λ) = −½ λᵀWλ + bᵀλ − ½ fᵀK⁻¹f``, ``W = N K⁻¹ Nᵀ``, ``b = N K⁻¹ f − d``, for a step ρ;
  it converges iff ``0 < ρ < 2/λ_max(W)``, and past the bound the status is ``diverged``.
- :func:`hertz_lesson`: Hertz's cylinder at a load, E and ν: the nodal pressure against
  ``p₀ √(1 − x²/a²)``, the contact width and the active set.
- :func:`prices_lesson`: the bogie with the rail under wheel 2 at gap ``d₂``: the envelope
  theorem ``∂J*/∂dᵢ = −λᵢ`` checked by central differences of the optimal energy.
- :func:`race_lesson`: several methods on one cylinder at one tolerance: iterations, time,
  status and the certificate's residuals side by side.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import numpy as np

import signorini
from signorini.api import Result

__all__ = ["BOGIE_GAPS", "HERTZ_FAST", "RACE_METHODS", "HertzLesson", "PricesLesson", "RaceRow",
           "UzawaLesson", "bogie", "dual_function", "hertz_lesson", "prices_lesson", "race_lesson",
           "uzawa_lesson", "uzawa_step_bound"]

#: the rail's gaps under the bogie's two wheels
BOGIE_GAPS = (0.0, 0.3)
#: the cylinder meshed by Triangle (the fast mesher) at a modest fineness: a re-solve per slider move
HERTZ_FAST = {"mesher": "triangle", "n_contact": 20}
#: the methods the race offers (those installed are shown)
RACE_METHODS = ("pdas", "nested", "condensed", "uzawa", "uzawa-nesterov", "qp-clarabel",
                "qp-osqp", "qp-proxqp", "qp-piqp")
#: the Uzawa lesson's tolerance and the most iterates it draws
UZAWA_TOL = 1e-6
DRAWN_ITERATES = 200
#: the relative step of the prices lesson's central differences
PRICE_STEP = 1e-5


def bogie(gaps: tuple[float, float] = BOGIE_GAPS, lowering: float = 1.0, *, ell: float = 1.0,
          EI: float = 10.0, k_v: float = 1.0, k_theta: float = 0.25) -> signorini.ContactProblem:
    """The bogie: a frame of two Hermite beam elements on a sprung mount lowered by ``lowering``,
    its two wheels over a rail at ``gaps`` (``−w₁ ≤ g₁``, ``−w₂ ≤ g₂``), as a plain QP."""
    h = ell
    element = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h**2, -6 * h, 2 * h**2],
                                    [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h**2, -6 * h, 4 * h**2]])
    K = np.zeros((6, 6))
    for first in (0, 2):
        K[first:first + 4, first:first + 4] += element
    K[2, 2] += k_v
    K[3, 3] += k_theta
    f = np.zeros(6)
    f[2] = -k_v * lowering
    N = np.zeros((2, 6))
    N[0, 0] = N[1, 4] = -1.0
    return signorini.ContactProblem.from_qp(K=K, f=f, N=N, d=np.asarray(gaps, dtype=float))


def dual_function(problem: signorini.ContactProblem) -> tuple[np.ndarray, np.ndarray, float]:
    """``W``, ``b`` and the constant of ``D(λ) = −½λᵀWλ + bᵀλ + c`` in the problem's own units."""
    K, f, N, d = problem.qp()
    K = K.toarray() if hasattr(K, "toarray") else np.asarray(K, dtype=float)
    N = N.toarray() if hasattr(N, "toarray") else np.asarray(N, dtype=float)
    K_inv_f, K_inv_Nt = np.linalg.solve(K, f), np.linalg.solve(K, N.T)
    return N @ K_inv_Nt, N @ K_inv_f - d, -0.5 * float(f @ K_inv_f)


@dataclass(frozen=True)
class UzawaLesson:
    """Uzawa on the bogie at step ``rho``: the package's run and its iterates (own units)."""

    rho: float
    bound: float           # 2 / λ_max(W), the package's own estimate
    result: Result
    iterates: np.ndarray   # the first DRAWN_ITERATES multipliers, one row per iteration
    maximiser: np.ndarray  # λ* from pdas
    W: np.ndarray
    b: np.ndarray
    constant: float


@functools.lru_cache(maxsize=1)
def _bogie_exact() -> Result:
    return signorini.solve(bogie(), "pdas", tol=1e-12)


def uzawa_step_bound() -> float:
    """``2/λ_max(W)`` of the bogie, as the package's Uzawa reports it (one short run)."""
    extras = signorini.solve(bogie(), "uzawa", max_iter=1).solution.extras
    return extras["rho"] / extras["rho_over_bound"]


def uzawa_lesson(rho: float) -> UzawaLesson:
    """Run the package's Uzawa on the bogie with step ``rho`` and record its iterates."""
    problem = bogie()
    iterates: list[np.ndarray] = []

    def record(iteration: int, lam: np.ndarray, displacement) -> None:
        if len(iterates) < DRAWN_ITERATES:
            iterates.append(lam * problem.scales.force)

    result = signorini.solve(problem, "uzawa", tol=UZAWA_TOL, rho=rho, callback=record)
    extras = result.solution.extras
    W, b, constant = dual_function(problem)
    return UzawaLesson(rho=rho, bound=extras["rho"] / extras["rho_over_bound"], result=result,
                       iterates=np.array(iterates).reshape(-1, problem.m),
                       maximiser=_bogie_exact().force, W=W, b=b, constant=constant)


@dataclass(frozen=True)
class HertzLesson:
    """Hertz's cylinder at load ``P``, modulus ``E`` and Poisson's ratio ``nu``."""

    P: float
    E: float
    nu: float
    result: Result
    x: np.ndarray          # candidates sorted by distance from the first point of contact
    pressure: np.ndarray   # nodal pressure in that order
    active: np.ndarray     # in contact, in that order
    a: float               # contact half-width of the fitted Hertz profile
    a_ref: float           # Hertz's half-width
    p0: float              # peak of the fitted profile
    p0_ref: float          # Hertz's peak pressure

    def hertz_pressure(self, x: np.ndarray) -> np.ndarray:
        """Hertz's ``p₀ √(1 − x²/a²)`` inside the contact, zero outside."""
        inside = np.clip(1.0 - (np.asarray(x) / self.a_ref) ** 2, 0.0, None)
        return self.p0_ref * np.sqrt(inside)


def hertz_lesson(P: float, E: float = 1.0, nu: float = 0.3) -> HertzLesson:
    """Solve the cylinder (Triangle's mesh, :data:`HERTZ_FAST`) with pdas at ``P``, ``E``, ``nu``."""
    result = signorini.solve("hertz-cylinder", "pdas", params={**HERTZ_FAST, "P": P, "E": E, "nu": nu})
    order = np.argsort(result.x)
    hertz = result.hertz
    return HertzLesson(P=P, E=E, nu=nu, result=result, x=result.x[order],
                       pressure=result.pressure[order], active=result.active[order], a=hertz.a,
                       a_ref=hertz.a_ref, p0=hertz.p0, p0_ref=hertz.p0_ref)


@dataclass(frozen=True)
class PricesLesson:
    """The bogie with the rail under wheel 2 at ``gap``, lowered by ``lowering``."""

    gap: float
    lowering: float
    result: Result
    prices: np.ndarray     # −∂J*/∂dᵢ by central differences of the re-solved optimal energy
    curve_gaps: np.ndarray  # J*(g₂) around the point, for the figure
    curve_energy: np.ndarray

    @property
    def force(self) -> np.ndarray:
        return self.result.force

    @property
    def envelope_error(self) -> float:
        """``max |λᵢ − (−∂J*/∂dᵢ)| / max(‖λ‖∞, 1e-300)``: the envelope theorem's miss."""
        return float(np.max(np.abs(self.force - self.prices)) / max(np.max(np.abs(self.force)), 1e-300))


def _optimal_energy(gaps: tuple[float, float], lowering: float) -> float:
    return signorini.solve(bogie(gaps, lowering), "pdas", tol=1e-12).energy


@functools.lru_cache(maxsize=16)
def _energy_curve(lowering: float) -> tuple[np.ndarray, np.ndarray]:
    gaps = np.linspace(-0.2, 2.4, 27)
    return gaps, np.array([_optimal_energy((0.0, g), lowering) for g in gaps])


def prices_lesson(gap: float, lowering: float = 1.0) -> PricesLesson:
    """Solve the bogie at (``gap``, ``lowering``) and price both gaps by two re-solves each."""
    gaps = np.array([0.0, gap])
    result = signorini.solve(bogie(tuple(gaps), lowering), "pdas", tol=1e-12)
    h = PRICE_STEP * max(float(np.max(np.abs(result.u))), 1e-3)
    prices = np.array([-(_optimal_energy(tuple(gaps + h * e), lowering)
                         - _optimal_energy(tuple(gaps - h * e), lowering)) / (2 * h)
                       for e in np.eye(2)])
    curve_gaps, curve_energy = _energy_curve(lowering)
    return PricesLesson(gap=gap, lowering=lowering, result=result, prices=prices,
                        curve_gaps=curve_gaps, curve_energy=curve_energy)


@dataclass(frozen=True)
class RaceRow:
    """One method's run in the race."""

    method: str
    status: str
    iterations: int
    seconds: float
    worst: tuple[str, float]  # the certificate's largest residual and its name


@functools.lru_cache(maxsize=1)
def _race_problem() -> signorini.ContactProblem:
    return signorini.at_load(signorini.build_problem("hertz-cylinder", params=HERTZ_FAST))


def race_lesson(methods: list[str] | tuple[str, ...], tol: float,
                max_iter: int = 20_000) -> list[RaceRow]:
    """Each method on the same cylinder at ``tol``: status, iterations, wall time, residuals."""
    problem = _race_problem()
    rows = []
    for method in methods:
        start = time.perf_counter()
        result = signorini.solve(problem, method, tol=tol, max_iter=max_iter)
        rows.append(RaceRow(method=method, status=result.status, iterations=result.iterations,
                            seconds=time.perf_counter() - start,
                            worst=result.certificate.worst()))
    return rows
