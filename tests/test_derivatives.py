"""Derivatives of the contact answer: against finite differences of exact re-solves, adjoint,
the envelope theorem, the block's linear law and Hertz's exponents; their cost in back-solves."""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini.errors import InputError
from signorini.numerics.factor import counting


def _rel(a, b) -> float:
    return float(np.linalg.norm(np.ravel(a) - np.ravel(b)) / np.linalg.norm(np.ravel(b)))


def _from_qp_in_mm() -> signorini.Result:
    """The cylinder's QP handed over as arrays in mm and MPa (no scene, no scales)."""
    scene = signorini.solve("hertz-cylinder", params={"R": 10.0, "E": 2.1e5, "n_contact": 20})
    p = scene.problem
    qp = signorini.ContactProblem.from_qp(*p.qp(), weights=p.weights * p.scales.weight)
    return signorini.solve(qp, "pdas")


RELAXED = {"hertz-cylinder": {"mesher": "relaxed", "n_contact": 40, "grading": 0.15},
           "hertz-sphere": {"mesher": "relaxed", "n_contact": 60, "grading": 0.15}}


@pytest.fixture(scope="module")
def results() -> dict[str, signorini.Result]:
    # the Hertz discs on the relaxed meshes docs/derivatives.md measured the fitted a's slope on
    found = {scene: signorini.solve(scene, "pdas", params=RELAXED.get(scene, {}))
             for scene in ("hertz-cylinder", "hertz-sphere", "block")}
    found["from_qp"] = _from_qp_in_mm()
    assert all(result.converged for result in found.values())
    return found


def _directions(result: signorini.Result, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A load change and a gap change of the answer's own sizes (user's units)."""
    rng = np.random.default_rng(seed)
    force = np.max(np.abs(result.force))
    gap = np.max(np.abs(result.u))
    return rng.standard_normal(result.problem.n) * force, rng.standard_normal(result.problem.m) * gap


def _resolve(result: signorini.Result, df: np.ndarray, dd: np.ndarray, h: float):
    """u and the forces (user's units) of the QP with f + h df and d + h dd, solved anew."""
    p, s = result.problem, result.problem.scales
    moved = p.with_data(f=p.f + h * df / s.force, d=p.d + h * dd / s.displacement)
    again = signorini.solve(moved, "pdas")
    assert again.converged
    return again.u, again.force, again.energy


@pytest.mark.parametrize("name", ["hertz-cylinder", "hertz-sphere", "block", "from_qp"])
def test_jvp_agrees_with_central_differences_of_exact_resolves(results, name):
    result = results[name]
    df, dd = _directions(result)
    h = 1e-6  # small enough that no candidate changes sides; the answer is affine on one side
    tangent = result.jvp(df, dd)
    assert not tangent.one_sided
    du, dforce = tangent
    plus, minus = _resolve(result, df, dd, h), _resolve(result, df, dd, -h)
    assert _rel(du, (plus[0] - minus[0]) / (2 * h)) < 1e-5
    assert _rel(dforce, (plus[1] - minus[1]) / (2 * h)) < 1e-5


@pytest.mark.parametrize("name", ["hertz-cylinder", "from_qp"])
def test_jvp_and_vjp_are_adjoint(results, name):
    result = results[name]
    df, dd = _directions(result, 1)
    gu, gforce = _directions(result, 2)
    gu, gforce = gu / np.max(np.abs(result.u)), gforce / np.max(np.abs(result.force)) ** 2
    du, dforce = result.jvp(df, dd)
    gf, gd = result.vjp(gu, gforce)
    left, right = gu @ du + gforce @ dforce, gf @ df + gd @ dd
    assert abs(left - right) <= 1e-8 * (abs(gu) @ abs(du) + abs(gforce) @ abs(dforce))


@pytest.mark.parametrize("name", ["hertz-cylinder", "from_qp"])
def test_the_multiplier_is_the_price_of_the_gap(results, name):
    """The envelope theorem: dJ*/dd = −λ, J* the optimal energy."""
    result = results[name]
    _, dd = _directions(result, 3)
    h, still = 1e-6, np.zeros(result.problem.n)
    slope = (_resolve(result, still, dd, h)[2] - _resolve(result, still, dd, -h)[2]) / (2 * h)
    price = -result.force @ dd
    assert abs(slope - price) <= 1e-4 * abs(price)


def test_the_block_obeys_its_linear_law():
    result = signorini.solve("block")
    P, params = result.total_force, result.problem.model.params
    by_push = signorini.derivative(result, "total_force", "delta")
    by_modulus = signorini.derivative(result, "total_force", "E")
    assert by_push.value == pytest.approx(P, rel=1e-12)
    assert by_push.derivative == pytest.approx(P / params["delta"], rel=1e-6)
    assert by_modulus.derivative == pytest.approx(P / params["E"], rel=1e-6)
    assert signorini.derivative("block", "total_force", "E").derivative == \
        pytest.approx(P / params["E"], rel=1e-6)


def test_poisson_and_the_obstacle_agree_with_resolves_of_the_scene():
    """ν enters K through its two Lamé parts, the obstacle's position d: both against re-solves."""
    nu, h = 0.3, 1e-5
    slope = signorini.derivative("block", "total_force", "nu", params={"nu": nu}).derivative
    ends = [signorini.solve("block", params={"nu": nu + s}).total_force for s in (h, -h)]
    assert slope == pytest.approx((ends[0] - ends[1]) / (2 * h), rel=1e-5)
    result = signorini.solve("block")
    moved = signorini.derivative(result, "total_force", "obstacle").derivative
    pushed = signorini.derivative(result, "total_force", "delta").derivative
    assert moved == pytest.approx(pushed, rel=1e-9)  # raising the obstacle is pushing the block


#: Hertz's equilibrium between the load, p₀ and a: P = π a p₀ / 2 (cylinder), 2π a² p₀ / 3 (sphere),
#: so d ln a / d ln P = (1 − d ln p₀ / d ln P) / (the power of a in it)
POWER_OF_A = {"hertz-cylinder": 1, "hertz-sphere": 2}


@pytest.mark.parametrize("name, exponent", [("hertz-cylinder", 1 / 2), ("hertz-sphere", 1 / 3)])
def test_hertz_exponents_come_out_of_the_fitted_outputs(results, name, exponent):
    result = results[name]
    P = result.total_force
    p0 = signorini.derivative(result, "p0", "P")
    a = signorini.derivative(result, "a", "P")
    assert p0.value == pytest.approx(result.hertz.p0, rel=1e-12)
    assert a.value == pytest.approx(result.hertz.a, rel=1e-12)
    of_p0 = p0.derivative * P / p0.value
    assert of_p0 == pytest.approx(exponent, rel=0.01)
    # the a of Hertz's equilibrium with the fitted p₀ and the load: within 1 % too
    assert (1 - of_p0) / POWER_OF_A[name] == pytest.approx(exponent, rel=0.01)
    # the fitted a's slope at one active set drifts across each node's entry, about ±3 % around
    # Hertz's on these meshes (docs/derivatives.md: a sawtooth in the load, not an error of it)
    assert a.derivative * P / a.value == pytest.approx(exponent, rel=0.05)
    total = signorini.derivative(result, "total_force", "P")
    assert total.derivative == pytest.approx(1.0, rel=1e-9)  # load control holds the load at P


def test_a_derivative_costs_back_solves_once_factorised(results):
    result = signorini.solve("hertz-cylinder", "pdas")
    df, dd = _directions(result)
    with counting() as first:
        result.jvp(df, dd)
    assert (first.factorisations, first.back_solves) == (1, 1)
    with counting() as after:
        result.vjp(df, dd)
        signorini.derivative(result, "total_force", "P")  # the push moves too: two right-hand sides
    assert (after.factorisations, after.back_solves) == (0, 3)


def test_a_kept_factorisation_makes_the_first_derivative_back_solves_only():
    """``keep_factor=True``: pdas's last factorisation pins the final active set, and is reused."""
    kept = signorini.solve("hertz-cylinder", "pdas", keep_factor=True)
    assert kept.solution.factor is not None
    df, dd = _directions(kept)
    with counting() as work:
        tangent = kept.jvp(df, dd)
    assert (work.factorisations, work.back_solves) == (0, 1)
    assert kept.solution.factor is None  # handed over to the derivatives, not kept twice
    fresh = signorini.solve("hertz-cylinder", "pdas")
    assert fresh.solution.factor is None  # let go after judging, by default
    assert _rel(tangent.du, fresh.jvp(df, dd).du) < 1e-10


def test_a_parameter_that_moves_the_mesh_is_refused():
    with pytest.raises(signorini.InputError, match="shape derivatives are not provided"):
        signorini.derivative("hertz-cylinder", "total_force", "R")
    with pytest.raises(signorini.InputError, match="differentiate with respect to P"):
        signorini.derivative("hertz-cylinder", "total_force", "delta")
    with pytest.raises(signorini.InputError, match="output must be one of"):
        signorini.derivative("block", "width", "E")


def test_a_weakly_active_node_makes_the_derivative_one_sided():
    """The block touching an obstacle shaped to its unsupported bottom: weak nodes are listed,
    and the two sides differ."""
    result = signorini.solve("block", "pdas", params={"touching": 0.25})
    assert result.converged
    n = result.problem.n
    pressing = -np.ones(result.problem.m) * np.max(np.abs(result.u))  # close every gap
    tangent = result.jvp(np.zeros(n), pressing)
    assert tangent.one_sided and tangent.weakly_active.size
    inside, outside = result.jvp(np.zeros(n), pressing, side="in"), result.jvp(np.zeros(n), pressing,
                                                                                side="out")
    assert not np.allclose(inside.dforce, outside.dforce)
    assert np.all(tangent.dforce >= -1e-12 * np.max(np.abs(tangent.dforce)))


@pytest.mark.parametrize("df, said", [([1j, 0], "df must be"), ("abc", "df must be"),
                                      ([[1.0], [2.0, 3.0]], "df must be")])
def test_a_change_that_is_not_real_numbers_names_its_argument(results, df, said):
    with pytest.raises(InputError, match=said):
        results["block"].jvp(df=df)
    full = np.full(results["block"].problem.n, 1j)  # complex of the right size: not cast to real
    with pytest.raises(InputError, match="df must be"):
        results["block"].jvp(df=full)


def test_an_answer_that_did_not_converge_has_no_derivative_by_any_door():
    stopped = signorini.solve("block", "uzawa", max_iter=2)
    assert stopped.status == "max_iter"
    for door in (lambda: stopped.jvp(), lambda: stopped.vjp(),
                 lambda: signorini.derivative(stopped, "total_force", "E")):
        with pytest.raises(signorini.errors.SolverError, match="only an exact answer"):
            door()


@pytest.mark.parametrize("at", [(float("nan"), 0.0), (0.0,), (1.0, 2.0, 3.0), "here"])
def test_a_point_that_is_not_one_names_at(results, at):
    with pytest.raises(InputError, match="at must be a point of 2 finite coordinates"):
        signorini.derivative(results["block"], "displacement", "E", at=at)
