"""Derivatives of a scene's physical outputs with respect to its parameters, on its mesh.

Total force, energy, the displacement at a point, nodal pressures and Hertz's fitted p₀
and a, with respect to E, ν, the load P or push δ and the obstacle's position: each enters
K, f and d analytically (:func:`change`), and the answer moves by the active-set system of
:class:`signorini.derivatives.implicit.Sensitivity` (:func:`scene_tangent`). The discrete contact
width is piecewise constant in these data, so it has no derivative; the fitted ``a`` is smooth.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from signorini.derivatives.implicit import Sensitivity, exact_answer
from signorini.errors import InputError
from signorini.fem.assembly import lame_stiffness, nodal_dofs
from signorini import load_control
from signorini.references.profile import contact_profile, hertz_fit, hertz_fit_tangent
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.reprs import short_repr
from signorini.scenes import build_problem
from signorini.scenes.base import scene_params
from signorini.scenes.build import coarse_problem
from signorini.solvers.registry import check_request

OUTPUTS = ("total_force", "energy", "displacement", "pressure", "p0", "a")
PARAMETERS = ("E", "nu", "E1", "E2", "nu1", "nu2", "P", "delta", "obstacle")


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
    return problem.model.push is not None and problem.model.push.target is not None


def change(problem: ContactProblem, solution: ContactSolution, wrt: str) -> Change:
    """The change of K, f, d and the target load per unit of the scene parameter ``wrt``."""
    model, push, s = problem.model, problem.model.push, problem.scales
    if push is None:
        raise InputError("derivatives with respect to scene parameters need a scene "
                         "(a problem from ContactProblem.from_qp has none): use Result.jvp")
    zero_n, zero_m = np.zeros(problem.n), np.zeros(problem.m)
    u = solution.u
    lift = push.scale * push.f1  # the load the prescribed push puts on the free dofs
    if wrt.startswith(("E", "nu")):  # one body's material: its rows of K, f alone
        name, on, E, nu, volumetric = _material(problem, wrt)
        if name == "nu":
            return _poisson_change(problem, u, E, nu, volumetric, on)
        return Change(np.where(on, problem.K @ u, 0.0) / E, np.where(on, lift, 0.0) / E, zero_m)
    if wrt == "P":
        if not _load_controlled(problem):
            raise InputError(f"{problem.name or 'this scene'} is loaded by a prescribed push, not "
                             "a target load: differentiate with respect to delta")
        return Change(zero_n, zero_n, zero_m, target=1.0 / s.force)
    if wrt == "delta":
        if _load_controlled(problem):
            raise InputError(f"{problem.name or 'this scene'} is loaded by a target load P, which "
                             "sets the push: differentiate with respect to P (or build the scene "
                             "with delta=)")
        if push.delta is None:
            raise InputError(f"{problem.name or 'this scene'} names no push delta to differentiate "
                             "with respect to: build it from a scene with a delta parameter")
        ratio = push.scale / push.delta  # the push moves in proportion to delta
        return Change(zero_n, push.f1 * ratio, push.d1 * ratio)
    if wrt == "obstacle":  # towards the body along the load axis: each gap shrinks by cᵢ
        tilt = np.ones(problem.m) if push.resultant is None else push.resultant
        return Change(zero_n, zero_n, -tilt / s.displacement)
    raise InputError(f"wrt must be one of {', '.join(PARAMETERS)}, got {wrt!r}")


def _material(problem: ContactProblem, wrt: str) -> tuple[str, np.ndarray, float, float, str]:
    """``("E" or "nu", the free dofs it acts on, the body's E, ν and volumetric integration)``
    of ``wrt``: ``E``/``nu`` for one body, ``E1``/``nu1`` (the first body's, the slave) and
    ``E2``/``nu2`` for two."""
    model = problem.model
    name, body = wrt.rstrip("12"), wrt[len(wrt.rstrip("12")):]
    if not body and model.materials:
        raise InputError(f"{problem.name or 'this scene'} has two bodies: differentiate with "
                         f"respect to {wrt}1 or {wrt}2")
    if body and not model.materials:
        raise InputError(f"{problem.name or 'this scene'} has one body: differentiate with "
                         f"respect to {name}")
    if not body:
        return name, np.ones(problem.n, dtype=bool), model.E, model.nu, model.volumetric
    counts = [material[0] for material in model.materials]
    first = sum(counts[:int(body) - 1])
    on = np.zeros(model.prescribed.size, dtype=bool)
    on[nodal_dofs(model.mesh)[:, np.unique(model.mesh.t[:, first:first + counts[int(body) - 1]])]] = True
    _, E, nu, volumetric = model.materials[int(body) - 1]
    return name, on[model.free_dofs], E, nu, volumetric


def _poisson_change(problem: ContactProblem, u: np.ndarray, E: float, nu: float,
                    volumetric: str, on: np.ndarray) -> Change:
    """∂K/∂ν from K's two Lamé parts, ``∂K/∂ν = E (∂Λ/∂ν K_Λ + ∂μ/∂ν K_μ)`` (exact), on the
    free dofs ``on`` of the body of modulus E and ratio ν (K is block diagonal by body)."""
    model, s = problem.model, problem.scales
    k = 1 if (model.axisymmetric or model.mesh.p.shape[0] == 3) else 0
    E = E * s.displacement * s.length ** k / s.force  # E in the problem's units
    lame = (1 + 2 * nu ** 2) / ((1 + nu) * (1 - 2 * nu)) ** 2, -0.5 / (1 + nu) ** 2
    dK = lame_stiffness(model.mesh, E * lame[0], E * lame[1], axisymmetric=model.axisymmetric,
                        volumetric=volumetric)
    free = model.free_dofs
    on_free, prescribed = np.zeros(model.prescribed.size), model.prescribed.copy()
    on_free[free] = u
    prescribed[free] = 0.0
    return Change(np.where(on, (dK @ on_free)[free], 0.0),
                  np.where(on, -(dK @ prescribed)[free], 0.0), np.zeros(problem.m))


def scene_tangent(sensitivity: Sensitivity, delta: Change) -> tuple[np.ndarray, np.ndarray, float]:
    """``(du, dλ, ds)`` for a change of the data; a load-controlled problem keeps its load
    ``μ Σ cᵢ λᵢ`` at the target by moving its push s (one more right-hand side)."""
    problem = sensitivity.problem
    push = problem.model.push
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
    s, model = problem.scales, problem.model
    profile = contact_profile(problem, solution)
    du, dlam, ds = tangent if tangent is not None else (None, None, 0.0)
    if output == "total_force":
        slope = None if du is None else problem.total_contact_force(dlam) * s.force
        return profile.total_force, slope
    dpressure = None if du is None else dlam * s.force / (problem.weights * s.weight)
    if output == "pressure":
        return profile.pressure, dpressure
    if output in ("p0", "a"):
        which = 0 if output == "p0" else 1
        value = hertz_fit(profile.x, profile.pressure, profile.active)[which]
        if du is None:
            return value, None
        return value, hertz_fit_tangent(profile.x, profile.pressure, profile.active, dpressure)[which]
    if output == "energy":
        u, lam = solution.u, solution.lam
        value = problem.energy(u) * s.force * s.displacement
        if du is None:
            return value, None
        push = problem.model.push
        f = delta.f + (ds * push.f1 if push is not None else 0.0)
        d = delta.d + (ds * push.d1 if push is not None else 0.0)
        slope = 0.5 * u @ delta.Ku - f @ u - lam @ d  # the envelope theorem
        return value, slope * s.force * s.displacement
    if output == "displacement":
        if at is None or model.mesh is None:
            raise InputError("output 'displacement' needs a point: at=(x, y) in the scene's units")
        mesh = model.mesh
        point = _point(at, mesh.p.shape[0]) / s.length
        node = int(np.argmin(np.linalg.norm(mesh.p - point[:, None], axis=0)))
        dofs = np.arange(mesh.p.shape[0]) + mesh.p.shape[0] * node
        value = problem.model.expand(solution.u)[dofs] * s.displacement
        if du is None:
            return value, None
        full = model.prescribed * (ds / model.push.scale if model.push is not None else 0.0)
        full[model.free_dofs] = du
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
    (Hertz's profile fitted to the pressures, :func:`signorini.references.profile.hertz_fit`);
    ``wrt`` one of ``E``, ``nu`` (``E1``, ``E2``, ``nu1``, ``nu2``: each body's of a two-body
    scene), ``P`` (a load-controlled scene's target
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
        request = check_request(method)  # before the scene is built
        problem = build_problem(scene, params=scene_params(params), solved_by=request.method)
        problem, solution, _ = load_control.solve(problem, request, coarse=coarse_problem,
                                                  keep_factor=True)
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


__all__ = ["Change", "OUTPUTS", "PARAMETERS", "SceneDerivative", "change", "derivative", "outputs",
           "scene_tangent"]
