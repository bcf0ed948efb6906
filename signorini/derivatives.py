"""Derivatives of the contact answer, by implicit differentiation of the KKT conditions.

On the final active set A the answer solves the linear system

    K u + N_Aᵀ λ_A = f,    N_A u = d_A,    λ = 0 off A,

so a change ``(df, dd)`` of the data moves it by the solution of the same system,
``[K N_Aᵀ; N_A 0] [du; dλ_A] = [df; dd_A]``: with the factorisation a method
already holds, back-solves only. The matrix is symmetric, so the adjoint
(``vjp``) is the same solve. A change of K enters as ``df = −dK u``.

A weakly active candidate (gap 0 and force 0) may enter or leave the contact:
there the answer is differentiable from one side only. ``side="auto"`` gives
the directional derivative along ``+(df, dd)`` (a node presses when its gap
would close, and lets go when its force would turn negative), ``"in"`` and
``"out"`` keep every weak node in or out of A; every answer lists the weak nodes.

:func:`derivative` differentiates a scene's physical outputs (total force,
energy, the displacement at a point, nodal pressures, Hertz's fitted p₀ and
a) with respect to E, ν, the load P or push δ and the obstacle's position,
all of which enter K, f and d analytically, on the scene's mesh as built.
The discrete contact width is piecewise constant in these data (it jumps
from node to node), so it has no derivative; the fitted ``a`` is smooth.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from skfem.models.elasticity import lame_parameters

from signorini.errors import InputError, SolverError
from signorini.fem.assembly import lame_stiffness
from signorini.kkt import ACTIVE, WEAK, classify
from signorini.loading import solve as load_control
from signorini.pressure import contact_profile, hertz_fit, hertz_fit_tangent
from signorini.problem import ContactProblem
from signorini.reprs import short_repr
from signorini.scenes import build_problem
from signorini.scenes.base import scene_params
from signorini.scenes.build import coarse_problem
from signorini.numerics.factor import ActiveSetSolver
from signorini.solution import ContactSolution

SIDES = ("auto", "in", "out")
OUTPUTS = ("total_force", "energy", "displacement", "pressure", "p0", "a")
PARAMETERS = ("E", "nu", "P", "delta", "obstacle")


@dataclass(frozen=True)
class Tangent:
    """``(du, dforce)`` from :meth:`Result.jvp <signorini.api.Result.jvp>`; unpacks as a pair.

    ``weakly_active`` lists the candidates touching with zero force: where it
    is not empty the derivative is one-sided, and ``pressed`` says which of
    them were kept in contact.
    """

    du: np.ndarray
    dforce: np.ndarray
    weakly_active: np.ndarray
    pressed: np.ndarray
    __repr__ = short_repr

    def __iter__(self):
        return iter((self.du, self.dforce))

    @property
    def one_sided(self) -> bool:
        return bool(self.weakly_active.size)


@dataclass(frozen=True)
class Cotangent:
    """``(gf, gd)`` from :meth:`Result.vjp <signorini.api.Result.vjp>`; unpacks as a pair.

    ``side`` is the branch at the ``weakly_active`` candidates (``in``: kept in
    contact, ``out``: let go).
    """

    gf: np.ndarray
    gd: np.ndarray
    weakly_active: np.ndarray
    side: str
    __repr__ = short_repr

    def __iter__(self):
        return iter((self.gf, self.gd))

    @property
    def one_sided(self) -> bool:
        return bool(self.weakly_active.size)


class Sensitivity:
    """The KKT system of one answer on its active set, factorised once, in the problem's units.

    ``factor`` is a factorisation the method holds (reused when it pins this
    very active set, else let go before another is made); otherwise the first
    solve makes one and later ones reuse it.
    """

    def __init__(self, problem: ContactProblem, solution: ContactSolution, factor: Any = None):
        exact_answer(solution)
        self.problem, self.solution = problem, solution
        labels = classify(problem, solution)
        self.strong = labels == ACTIVE
        self.weak = np.flatnonzero(labels == WEAK)
        self._system = ActiveSetSolver(problem.K, problem.N)
        self._factor = factor

    def solve(self, active: np.ndarray, f: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(du, dλ)`` on ``active`` (f: n or n × k, d: m or m × k), reusing the factorisation."""
        if not self._system.pins(active, self._factor):
            self._factor = None  # not this system's: let go before the solve makes another
        du, dlam = self._system.solve(active, f, d, factor=self._factor)
        if self._system.factor is not None:
            self._factor = self._system.factor
        return du, dlam

    def branch(self, side: str) -> np.ndarray:
        """The active set with every weak node in (``in``) or out (``out``)."""
        active = self.strong.copy()
        if side == "in":
            active[self.weak] = True
        return active

    def tangent(self, df: np.ndarray, dd: np.ndarray, side: str = "auto") -> tuple[np.ndarray, ...]:
        """``(du, dλ, pressed)`` for the change ``(df, dd)``; see the module's note on ``side``."""
        side = _side(side, SIDES)
        active = self.branch("out" if side == "auto" else side)
        du, dlam = self.solve(active, df, dd)
        if side == "auto":
            for _ in range(self.weak.size):  # a small active-set loop over the weak nodes only
                closing = (dd - self.problem.N @ du)[self.weak] < 0
                pulling = dlam[self.weak] < 0
                wanted = active.copy()
                wanted[self.weak[closing & ~active[self.weak]]] = True
                wanted[self.weak[pulling & active[self.weak]]] = False
                if np.array_equal(wanted, active):
                    break
                active = wanted
                du, dlam = self.solve(active, df, dd)
        return du, dlam, self.weak[active[self.weak]]

    def cotangent(self, gu: np.ndarray, glam: np.ndarray, side: str = "out") -> tuple[np.ndarray, ...]:
        """``(gf, gd)`` with ``⟨gu, du⟩ + ⟨gλ, dλ⟩ = ⟨gf, df⟩ + ⟨gd, dd⟩`` on one branch."""
        side = _side(side, ("in", "out"))
        active = self.branch(side)
        glam = np.where(active, glam, 0.0)
        gf, gd = self.solve(active, gu, glam)
        return gf, np.where(active, gd, 0.0)


def exact_answer(solution: ContactSolution) -> None:
    """SolverError unless ``solution`` is converged and finite: only an exact answer has a
    derivative (a ``max_iter`` answer's active set may not be the answer's)."""
    if solution.status != "converged":
        raise SolverError(f"the answer is {solution.status} ({solution.message}): only an exact "
                          "answer has a derivative; solve to convergence first")
    if not (np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))):
        raise SolverError("the answer is not finite: it has no derivative")


def _side(side: str, allowed: tuple[str, ...]) -> str:
    if side not in allowed:
        raise InputError(f"side must be one of {', '.join(allowed)}, got {side!r}")
    return side


def _vector(value: Any, size: int, name: str, unit: float) -> np.ndarray:
    if value is None:
        return np.zeros(size)
    try:
        array = np.asarray(value)
    except ValueError:  # a ragged list
        array = np.asarray(None)
    if array.dtype.kind not in "biuf":
        raise InputError(f"{name} must be {size} real numbers, got {str(value)[:60]}")
    array = array.astype(float)
    if array.shape != (size,):
        raise InputError(f"{name} must have shape ({size},), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} contains non-finite values")
    return array / unit


def jvp(sensitivity: Sensitivity, df: Any = None, dd: Any = None, side: str = "auto") -> Tangent:
    """``(du, dforce)`` for a change ``(df, dd)`` of the QP's load and gaps, in the user's units.

    ``df`` is in force units (n free dofs), ``dd`` in length units (m
    candidates); ``du`` in length units, ``dforce`` the nodal contact forces.
    """
    problem = sensitivity.problem
    s = problem.scales
    du, dlam, pressed = sensitivity.tangent(_vector(df, problem.n, "df", s.force),
                                            _vector(dd, problem.m, "dd", s.displacement), side)
    return Tangent(du * s.displacement, dlam * s.force, sensitivity.weak, pressed)


def vjp(sensitivity: Sensitivity, gu: Any = None, gforce: Any = None, side: str = "out") -> Cotangent:
    """``(gf, gd)``: the gradient of ``⟨gu, u⟩ + ⟨gforce, force⟩`` with respect to f and d."""
    problem = sensitivity.problem
    s = problem.scales
    gf, gd = sensitivity.cotangent(_vector(gu, problem.n, "gu", 1 / s.displacement),
                                   _vector(gforce, problem.m, "gforce", 1 / s.force), side)
    return Cotangent(gf / s.force, gd / s.displacement, sensitivity.weak, side)


# -- scene parameters ------------------------------------------------------------------------


@dataclass(frozen=True)
class Change:
    """How the QP's data move per unit of one parameter (problem's units).

    ``Ku`` is ``dK u`` (the stiffness's change applied to the answer), ``f``
    and ``d`` the changes of the load and gaps, ``target`` of the target load.
    """

    Ku: np.ndarray
    f: np.ndarray
    d: np.ndarray
    target: float = 0.0


@dataclass(frozen=True)
class SceneDerivative:
    """``d output / d wrt`` of one scene, in the scene's units, at ``value`` of the output.

    ``derivative`` is a number, or an array for ``pressure`` (per candidate)
    and ``displacement`` (per component). ``weakly_active`` lists candidates
    touching with zero force (the derivative is then one-sided: for an
    increase of the parameter).
    """

    output: str
    wrt: str
    value: Any
    derivative: Any
    weakly_active: np.ndarray
    result: Any = field(default=None, repr=False)
    __repr__ = short_repr


def _load_controlled(problem: ContactProblem) -> bool:
    return problem.push is not None and problem.push.target is not None


def change(problem: ContactProblem, solution: ContactSolution, wrt: str) -> Change:
    """The change of K, f, d and the target load per unit of the scene parameter ``wrt``."""
    disc, push, s = problem.discretisation, problem.push, problem.scales
    if disc is None or push is None:
        raise InputError("derivatives with respect to scene parameters need a scene "
                         "(a problem from ContactProblem.from_qp has none): use Result.jvp")
    zero_n, zero_m = np.zeros(problem.n), np.zeros(problem.m)
    u = solution.u
    lift = push.scale * push.f1  # the load the prescribed push puts on the free dofs
    if wrt == "E":  # K ∝ E, and so is the lift of the prescribed push
        return Change(problem.K @ u / disc.E, lift / disc.E, zero_m)
    if wrt == "nu":
        return _poisson_change(problem, u)
    if wrt == "P":
        if not _load_controlled(problem):
            raise InputError(f"{problem.scene or 'this scene'} is loaded by a prescribed push, not "
                             "a target load: differentiate with respect to delta")
        return Change(zero_n, zero_n, zero_m, target=1.0 / s.force)
    if wrt == "delta":
        if _load_controlled(problem):
            raise InputError(f"{problem.scene or 'this scene'} is loaded by a target load P, which "
                             "sets the push: differentiate with respect to P (or build the scene "
                             "with delta=)")
        if push.delta is None:
            raise InputError(f"{problem.scene or 'this scene'} names no push delta to differentiate "
                             "with respect to: build it from a scene with a delta parameter")
        ratio = push.scale / push.delta  # the push moves in proportion to delta
        return Change(zero_n, push.f1 * ratio, push.d1 * ratio)
    if wrt == "obstacle":  # towards the body along the load axis: each gap shrinks by cᵢ
        tilt = np.ones(problem.m) if push.resultant is None else push.resultant
        return Change(zero_n, zero_n, -tilt / s.displacement)
    raise InputError(f"wrt must be one of {', '.join(PARAMETERS)}, got {wrt!r}")


def _poisson_change(problem: ContactProblem, u: np.ndarray) -> Change:
    """∂K/∂ν from K's two Lamé parts, ``∂K/∂ν = E (∂Λ/∂ν K_Λ + ∂μ/∂ν K_μ)`` (exact)."""
    disc, s = problem.discretisation, problem.scales
    nu, k = disc.nu, 1 if (disc.axisymmetric or disc.mesh.p.shape[0] == 3) else 0
    E = disc.E * s.displacement * s.length ** k / s.force  # E in the problem's units
    lame = (1 + 2 * nu ** 2) / ((1 + nu) * (1 - 2 * nu)) ** 2, -0.5 / (1 + nu) ** 2
    dK = lame_stiffness(disc.mesh, E * lame[0], E * lame[1], axisymmetric=disc.axisymmetric,
                        volumetric=disc.volumetric)
    free = disc.free_dofs
    on_free, prescribed = np.zeros(disc.prescribed.size), disc.prescribed.copy()
    on_free[free] = u
    prescribed[free] = 0.0
    return Change((dK @ on_free)[free], -(dK @ prescribed)[free], np.zeros(problem.m))


def scene_tangent(sensitivity: Sensitivity, delta: Change) -> tuple[np.ndarray, np.ndarray, float]:
    """``(du, dλ, ds)`` for a change of the data; a load-controlled problem keeps its load
    ``μ Σ cᵢ λᵢ`` at the target by moving its push s (one more right-hand side)."""
    problem = sensitivity.problem
    push = problem.push
    f, d = delta.f - delta.Ku, delta.d
    if not _load_controlled(problem):
        du, dlam, _ = sensitivity.tangent(f, d)
        return du, dlam, 0.0
    tilt = np.ones(problem.m) if push.resultant is None else push.resultant
    du, dlam, _ = sensitivity.tangent(np.column_stack([f, push.f1]), np.column_stack([d, push.d1]),
                                      side="out" if sensitivity.weak.size else "auto")
    load = problem.force_multiplicity * (tilt @ dlam)
    ds = (delta.target - load[0]) / load[1]
    return du[:, 0] + ds * du[:, 1], dlam[:, 0] + ds * dlam[:, 1], float(ds)


def outputs(problem: ContactProblem, solution: ContactSolution, output: str, at: Any = None,
            tangent: tuple[np.ndarray, np.ndarray, float] | None = None,
            delta: Change | None = None) -> tuple[Any, Any]:
    """``(value, derivative)`` of one physical output (the derivative None without a tangent)."""
    s, disc = problem.scales, problem.discretisation
    profile = contact_profile(problem, solution)
    du, dlam, ds = tangent if tangent is not None else (None, None, 0.0)
    if output == "total_force":
        slope = None if du is None else problem.total_contact_force(dlam) * s.force
        return profile.total_force, slope
    if output == "pressure":
        unit = s.force / (problem.weights * s.weight)
        return profile.pressure, None if du is None else dlam * unit
    if output in ("p0", "a"):
        which = 0 if output == "p0" else 1
        value = hertz_fit(profile.x, profile.pressure, profile.active)[which]
        if du is None:
            return value, None
        dpressure = dlam * s.force / (problem.weights * s.weight)
        return value, hertz_fit_tangent(profile.x, profile.pressure, profile.active, dpressure)[which]
    if output == "energy":
        u, lam = solution.u, solution.lam
        value = problem.energy(u) * s.force * s.displacement
        if du is None:
            return value, None
        push = problem.push
        f = delta.f + (ds * push.f1 if push is not None else 0.0)
        d = delta.d + (ds * push.d1 if push is not None else 0.0)
        slope = 0.5 * u @ delta.Ku - f @ u - lam @ d  # the envelope theorem
        return value, slope * s.force * s.displacement
    if output == "displacement":
        if at is None or disc is None or disc.mesh is None:
            raise InputError("output 'displacement' needs a point: at=(x, y) in the scene's units")
        mesh = disc.mesh
        point = _point(at, mesh.p.shape[0]) / s.length
        node = int(np.argmin(np.linalg.norm(mesh.p - point[:, None], axis=0)))
        dofs = np.arange(mesh.p.shape[0]) + mesh.p.shape[0] * node
        value = problem.expand(solution.u)[dofs] * s.displacement
        if du is None:
            return value, None
        full = disc.prescribed * (ds / disc.push.scale if disc.push is not None else 0.0)
        full[disc.free_dofs] = du
        return value, full[dofs] * s.displacement
    raise InputError(f"output must be one of {', '.join(OUTPUTS)}, got {output!r}")


def _point(at: Any, dim: int) -> np.ndarray:
    try:
        point = np.asarray(at, dtype=float)
    except (TypeError, ValueError):
        point = np.full(dim + 1, np.nan)
    if point.shape != (dim,) or not np.all(np.isfinite(point)):
        raise InputError(f"at must be a point of {dim} finite coordinates in the scene's units, "
                         f"e.g. at=({', '.join(['0.0'] * dim)}), got {at!r}")
    return point


def derivative(scene: Any, output: str, wrt: str, *, params: dict[str, Any] | None = None,
               method: str = "auto", at: Any = None) -> SceneDerivative:
    """``d output / d wrt`` of a scene's answer, exactly, on the scene's mesh.

    ``scene`` is a scene's name (built with ``params`` and solved with
    ``method``) or a converged :class:`signorini.Result`. ``output`` is one of
    ``total_force``, ``energy`` (the optimal ½uᵀKu − fᵀu), ``displacement``
    (at the mesh node nearest ``at``), ``pressure`` (nodal), ``p0`` and ``a``
    (Hertz's profile fitted to the pressures, :func:`signorini.pressure.hertz_fit`);
    ``wrt`` one of ``E``, ``nu``, ``P`` (a load-controlled scene's target
    load), ``delta`` (a push-controlled scene's push) and ``obstacle`` (the
    obstacle's position along the load axis, towards the body). A parameter
    that moves the mesh is refused: shape derivatives are not provided.
    Cost: the solve, then two back-solves, with the method's factorisation
    when it pins the final active set (``pdas``), else one factorisation of
    the active-set system (K with the active dofs pinned) first.
    """
    if output not in OUTPUTS:
        raise InputError(f"output must be one of {', '.join(OUTPUTS)}, got {output!r}")
    if wrt not in PARAMETERS:
        raise InputError(f"the derivative with respect to {wrt!r} is not provided: {', '.join(PARAMETERS)} "
                         "enter K, f and d analytically; a parameter that moves or rebuilds the "
                         "mesh (R, W, H, refine...) needs a shape derivative, and shape "
                         "derivatives are not provided")
    if isinstance(scene, str):
        problem = build_problem(scene, params=scene_params(params), solved_by=method)
        problem, solution = load_control(problem, method, coarse=coarse_problem, keep_factor=True)
        result = None
    else:
        if params:
            raise InputError("params= builds a scene by name; a Result is differentiated as solved")
        problem, solution, result = scene.problem, scene.solution, scene
    exact_answer(solution)
    delta = change(problem, solution, wrt)
    sensitivity = Sensitivity(problem, solution, solution.factor) if result is None else result.sensitivity
    tangent = scene_tangent(sensitivity, delta)
    value, slope = outputs(problem, solution, output, at, tangent, delta)
    return SceneDerivative(output, wrt, value, slope, sensitivity.weak, result)


__all__ = ["Cotangent", "OUTPUTS", "PARAMETERS", "SIDES", "SceneDerivative", "Sensitivity",
           "Tangent", "derivative", "jvp", "vjp"]
