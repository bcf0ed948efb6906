"""Property-based tests on small random contact QPs (``synthetic.random_problem``).

Every installed method must be honest: when it reports ``converged`` the package's certificate
backs it. PDAS must agree with a brute-force enumeration of the active sets.
"""

import itertools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from signorini.errors import InputError
from signorini.certification.kkt import certificate
from signorini.solvers import registry
from signorini.solvers.base import rows_share_dofs
from synthetic import random_problem

TOL = 1e-8
SETTINGS = settings(max_examples=25, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])

METHODS = [m.name for m in registry.methods(installed_only=True) if m.family != "user"]


@st.composite
def problems(draw, max_condition=1e4):
    n = draw(st.integers(2, 12), label="n")
    m = draw(st.integers(1, n), label="m")
    seed = draw(st.integers(0, 2**32 - 1), label="seed")
    condition = draw(st.floats(1.0, max_condition, allow_nan=False), label="condition")
    return random_problem(n, m, seed, condition)


def brute_force(problem):
    """The KKT points found by solving the saddle-point system on every subset of constraints."""
    K, N = problem.K.toarray(), problem.N.toarray()
    n, m = problem.n, problem.m
    found = []
    for k in range(m + 1):
        for chosen in itertools.combinations(range(m), k):
            A = list(chosen)
            system = np.block([[K, N[A].T], [N[A], np.zeros((k, k))]])
            x = np.linalg.solve(system, np.concatenate([problem.f, problem.d[A]]))
            u, lam = x[:n], np.zeros(m)
            lam[A] = x[n:]
            force_scale = max(1.0, np.max(np.abs(lam)))
            gap_scale = max(1.0, np.max(np.abs(u)), np.max(np.abs(problem.d)))
            if (lam.min() >= -1e-9 * force_scale
                    and np.max(N @ u - problem.d) <= 1e-9 * gap_scale):
                found.append((u, lam))
    return found


def test_methods_are_listed():
    assert "pdas" in METHODS and "uzawa" in METHODS


@pytest.mark.parametrize("method", METHODS)
@SETTINGS
@given(problem=problems())
def test_a_converged_claim_satisfies_the_certificate(method, problem):
    if registry.get_method(method).bound_rows and rows_share_dofs(problem.N):
        with pytest.raises(InputError, match=f"method '{method}' .*share dofs"):  # declared
            registry.solve(problem, method, tol=TOL)
        return
    solution = registry.solve(problem, method, tol=TOL)
    assert solution.status in ("converged", "inaccurate", "max_iter", "diverged", "infeasible",
                               "failed")
    assert solution.lam.shape == (problem.m,) and solution.u.shape == (problem.n,)
    if solution.status == "converged":
        cert = certificate(problem, solution)
        name, worst = cert.worst()
        assert worst <= 10 * TOL, (name, worst, solution.message)
        assert np.all(np.isfinite(solution.u)) and np.all(np.isfinite(solution.lam))
    else:
        assert not solution.success


@SETTINGS
@given(problem=problems())
def test_pdas_matches_brute_force_enumeration(problem):
    solution = registry.solve(problem, "pdas", tol=TOL)
    found = brute_force(problem)
    assert found, "a strictly convex QP with full-row-rank N has a KKT point"
    u_ref, lam_ref = found[0]
    # N has full row rank and K is SPD: u and λ are unique
    for u, lam in found[1:]:
        np.testing.assert_allclose(u, u_ref, atol=1e-7 * max(1.0, np.abs(u_ref).max()))
        np.testing.assert_allclose(lam, lam_ref, atol=1e-7 * max(1.0, np.abs(lam_ref).max()))
    if solution.status != "converged":
        # PDAS may cycle on ill-conditioned problems (see the xfail below); it must say so
        assert solution.status == "max_iter", solution.message
        return
    np.testing.assert_allclose(solution.u, u_ref, rtol=0,
                               atol=1e-7 * max(1.0, np.abs(u_ref).max()))
    np.testing.assert_allclose(solution.lam, lam_ref, rtol=0,
                               atol=1e-7 * max(1.0, np.abs(lam_ref).max()))


@SETTINGS
@given(problem=problems(max_condition=100.0))
def test_pdas_converges_on_moderately_conditioned_problems(problem):
    solution = registry.solve(problem, "pdas", tol=TOL)
    assert solution.status == "converged", solution.message
    assert certificate(problem, solution).worst()[1] < 1e-10


def test_pdas_converges_on_an_ill_conditioned_random_problem():
    problem = random_problem(4, 4, 96, 1e4)
    solution = registry.solve(problem, "pdas", tol=TOL, max_iter=1000)
    assert solution.status == "converged", solution.message
