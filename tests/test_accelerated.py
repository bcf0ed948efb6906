"""Accelerated Uzawa (FISTA with restart) against the plain iteration and the exact answer."""

import pytest

import signorini
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.scenes import build_problem
from signorini.solvers.registry import solve


@pytest.fixture(scope="module")
def hertz():
    return signorini.at_load(build_problem("hertz-cylinder", params={"n_contact": 24, "grading": 0.3}))


def test_nesterov_reaches_the_exact_answer_in_fewer_iterations(hertz):
    exact = solve(hertz, "pdas", tol=1e-9)
    plain = solve(hertz, "uzawa", tol=1e-9)
    fast = solve(hertz, "uzawa-nesterov", tol=1e-9)
    assert plain.status == "converged"
    # the contraction of its steps alone would stop it with λ 1.4e-8 off at tol 1e-9: it goes on
    # until the certificate (its forward error of λ) backs the answer
    assert fast.status == "converged" and not fast.claimed_status, fast.message
    agreement = compare(hertz, exact, fast)
    assert agreement.lam_rel < 1e-8 and agreement.misclassified == 0
    assert fast.iterations * 5 < plain.iterations
    assert fast.extras["rho_over_bound"] == pytest.approx(0.5)


def test_acceleration_is_an_option_of_uzawa_too(hertz):
    via_option = solve(hertz, "uzawa", tol=1e-8, acceleration="nesterov", step_fraction=0.5)
    via_name = solve(hertz, "uzawa-nesterov", tol=1e-8)
    assert via_option.iterations == via_name.iterations
    with pytest.raises(InputError, match="acceleration"):
        solve(hertz, "uzawa", acceleration="heavy-ball")


def test_nesterov_beyond_its_step_bound_says_so():
    from synthetic import bogie

    problem = bogie()
    beyond = solve(problem, "uzawa-nesterov", max_iter=3, step_fraction=0.8)  # ρ·λ_max = 1.6
    assert beyond.status == "max_iter"
    assert "1.60 > 1" in beyond.message and "step_fraction" in beyond.message
    within = solve(problem, "uzawa-nesterov", max_iter=3)  # ρ·λ_max = 1
    # at the bound itself (ρ·λ_max = 1) nothing is beyond it: three steps are simply too few
    assert within.status == "max_iter"
    assert "bound" not in within.message and "step_fraction" not in within.message


@pytest.mark.parametrize("method", ["uzawa", "uzawa-nesterov"])
@pytest.mark.parametrize("refine, nu", [(2, 0.49), (4, 0.45), (4, 0.49)])
def test_a_dual_method_stops_certified_or_at_max_iter_on_a_users_qp_in_mm_mpa(method, refine, nu):
    """Its own stopping test is backed by the certificate: at tol 1e-9 on a user's block in
    mm–MPa (where the estimate of the distance to the answer alone stopped FISTA short)."""
    from test_from_qp_units import half_block

    K, f, N, d, weights, points = half_block(1.0, 2.1e5, refine, nu)
    problem = signorini.ContactProblem.from_qp(K, f, N, d, weights=weights, contact_points=points)
    result = signorini.solve(problem, method, tol=1e-9)
    assert result.status in ("converged", "max_iter"), result.message
    if result.status == "converged":
        assert result.certificate.worst()[1] <= 1e-9
    else:
        assert "the certificate did not" in result.message
