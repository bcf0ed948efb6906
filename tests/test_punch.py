"""The flat punch: force balance, ∫p = P, symmetry, the half-plane pressure away from the edges,
the edge singularity under refinement, rounded corners, and agreement of the methods."""

import numpy as np
import pytest

import signorini
from signorini.references.analytic import punch_load_between, punch_pressure
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.references.pressure import compare_punch, contact_profile, load_resultant
from signorini.scenes import build_problem
from signorini.solvers.registry import solve

SMALL = {"n_contact": 16, "grading": 0.5}


@pytest.fixture(scope="module")
def punch():
    problem = signorini.at_load(build_problem("punch", params=SMALL))
    return problem, solve(problem, "pdas", tol=1e-10)


def test_punch_formula_integrates_to_the_load():
    P, a = 3.0, 0.7
    x = np.linspace(-a, a, 400_001)[1:-1]
    # the integrable singularity: compare the closed form with a fine sum away from the edges
    inner = np.abs(x) <= 0.9 * a
    assert np.trapezoid(punch_pressure(x[inner], a, P), x[inner]) == pytest.approx(
        punch_load_between(-0.9 * a, 0.9 * a, a, P), rel=1e-5)
    assert punch_load_between(-a, a, a, P) == pytest.approx(P)
    assert punch_pressure(np.array([0.0]), a, P)[0] == pytest.approx(P / (np.pi * a))
    assert np.isnan(punch_pressure(np.array([a, 2 * a]), a, P)).all()


def test_force_balance_and_integral_of_pressure(punch):
    problem, solution = punch
    profile = contact_profile(problem, solution)
    P = problem.model.params["P"]
    # ∫p = P with the lumped pressure: Σ pᵢ wᵢ over the half model, times two
    integral = 2.0 * np.sum(profile.pressure * problem.weights * problem.scales.weight)
    assert integral == pytest.approx(P, rel=1e-12)
    assert load_resultant(problem, solution.lam) == pytest.approx(P, rel=1e-12)
    assert profile.applied_load == pytest.approx(P, rel=1e-9)
    assert np.all(profile.active)  # every node under a sharp punch touches


def test_pressure_away_from_the_edges_at_the_default_mesh():
    problem = signorini.at_load(build_problem("punch"))
    result = compare_punch(problem, solve(problem, "pdas", tol=1e-10))
    assert result.pressure_max_rel < 0.01  # |x| ≤ a/2
    assert result.pressure_l2_rel < 0.01
    assert result.force_balance < 1e-9 and result.target_rel < 1e-12


def test_edge_pressure_grows_like_one_over_root_h():
    """The singularity in the discrete answer: halving h multiplies the edge pressure by √2."""
    ratios = []
    for level in (0, 1, 2):
        problem = signorini.at_load(build_problem("punch", params={"refine": level, **SMALL}))
        result = compare_punch(problem, solve(problem, "pdas", tol=1e-10))
        ratios.append((result.edge_h, result.edge_over_centre, result.pressure_max_rel))
    h, edge, inner = map(np.array, zip(*ratios))
    slope = np.polyfit(np.log(h), np.log(edge), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.05)
    assert np.all(np.diff(inner) < 0)  # away from the edges the error falls


def test_whole_block_is_symmetric_and_equals_the_half(punch):
    half_problem, half = punch
    problem = signorini.at_load(build_problem("punch", params={"half": 0, **SMALL}))
    whole = solve(problem, "pdas", tol=1e-10)
    x = problem.contact_points[:, 0] * problem.scales.length
    p = contact_profile(problem, whole).pressure
    np.testing.assert_allclose(p[np.argsort(x)], p[np.argsort(-x)], rtol=1e-8)
    right = np.argsort(x)[x[np.argsort(x)] >= 0]
    np.testing.assert_allclose(p[right], contact_profile(half_problem, half).pressure, rtol=1e-7)
    assert load_resultant(problem, whole.lam) == pytest.approx(problem.model.params["P"], rel=1e-10)


@pytest.mark.parametrize("method", ["uzawa", "condensed"])
def test_methods_agree_with_pdas(punch, method):
    problem, exact = punch
    other = solve(problem, method, tol=1e-10)
    assert other.status == "converged"
    difference = compare(problem, exact, other)
    assert difference.lam_rel < 1e-6 and difference.misclassified == 0


@pytest.mark.slow
def test_rounded_corners_spread_the_contact_and_bound_the_pressure():
    def peaks(radius):
        out = []
        for level in (1, 2):
            params = {"corner_radius": radius, "load_ratio": 0.02, "refine": level, **SMALL}
            problem = signorini.at_load(build_problem("punch", params=params))
            solution = solve(problem, "pdas", tol=1e-10)
            out.append((problem, solution, contact_profile(problem, solution).pressure.max()))
        return out

    rounded = peaks(0.25)
    problem, solution, _ = rounded[0]
    assert solution.status == "converged"
    profile = contact_profile(problem, solution)
    x = problem.contact_points[:, 0] * problem.scales.length
    assert x[profile.active].max() > 1.0  # the contact reaches onto the rounded corner
    assert not profile.active[-1]  # but not to its end
    # force balance holds for the vertical resultant (normals tilt on the corner)
    assert load_resultant(problem, solution.lam) == pytest.approx(profile.applied_load, rel=1e-9)
    # halving h: the sharp edge's peak grows by √2, the rounded corner's settles
    sharp = peaks(0.0)
    assert sharp[1][2] / sharp[0][2] == pytest.approx(np.sqrt(2), rel=0.02)
    assert rounded[1][2] / rounded[0][2] < 1.1


@pytest.mark.parametrize("values, name", [
    ({"corner_radius": -0.1}, "corner_radius"),
    ({"half": 2}, "half"),
    ({"size": 1.0}, "size"),
    ({"n_contact": 1}, "n_contact"),
    ({"P": 0.0}, "P"),
    ({"load_ratio": 2.0}, "load_ratio"),
])
def test_bad_punch_parameters_name_themselves(values, name):
    with pytest.raises(InputError, match=rf"\b{name}="):
        signorini.at_load(build_problem("punch", params=values))


def test_two_load_parameters_raise():
    with pytest.raises(InputError, match="P and delta"):
        signorini.at_load(build_problem("punch", params={"P": 0.01, "delta": 0.001}))


def test_prescribed_delta_without_target():
    problem = signorini.at_load(build_problem("punch", params={"delta": 1e-3, **SMALL}))
    solution = solve(problem, "pdas", tol=1e-10)
    assert problem.model.params["P"] is None
    assert compare_punch(problem, solution).force_balance < 1e-9
