"""Accelerated Uzawa (FISTA with restart) against the plain iteration and the exact answer."""

import pytest

import signorini
from signorini.errors import InputError
from signorini.kkt import compare
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
    # its stopping test (the contraction of its steps) leaves λ 1.4e-8 off at tol 1e-9: it claims
    # convergence and the certificate's forward error of λ turns it down (docs/certificate.md)
    assert fast.claimed_status == "converged" and fast.status == "inaccurate"
    assert "contact force is not certified" in fast.message
    agreement = compare(hertz, exact, fast)
    assert agreement.lam_rel < 1e-6 and agreement.misclassified == 0
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
