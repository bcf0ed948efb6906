"""The ``qp-*`` methods (qpsolvers backends) and the ``cvxpy`` method.

Every method is checked against an exact answer computed here, independently of
any signorini solver: for the small dense problems of
:func:`synthetic.random_problem` all ``2ᵐ`` active sets are tried,
and the one whose equality-constrained KKT solution is feasible with ``λ ≥ 0``
is the answer (unique: K is SPD and N has full row rank).

A backend that is not installed shows up as a skip naming its module.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.sparse as sp

import signorini.solvers.cvxpy_ as cvxpy_method  # registers "cvxpy"
import signorini.solvers.qp as qp  # registers "qp-*"
from signorini.errors import InputError, SolverError
from signorini.certification.kkt import certificate
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.solvers import registry
from signorini.solvers.registry import get_method, solve
from synthetic import random_problem

registry.methods()  # every built-in method registered (the exact ones these tests compare with)

QP_METHODS = [backend.method_name for backend in qp.BACKENDS]
METHODS = [*QP_METHODS, "cvxpy"]
DENSE_METHODS = [b.method_name for b in qp.BACKENDS if b.dense]

#: (n, m, seed) of problems with some constraints active and some not (the last: all active)
CONTACT_CASES = [(8, 3, 0), (12, 5, 1), (12, 5, 3), (20, 6, 4), (12, 5, 6)]
#: a problem whose exact answer has no contact at all (λ = 0)
NO_CONTACT_CASE = (8, 3, 2)

#: tolerance asked for, and the bound on certificate residuals and on the relative
#: distance to the exact answer; methods not listed reach ``TIGHT``
TIGHT = (1e-9, 1e-6)
ACCURACY = {
    # first-order ADMM: 1e-9 is reached here only thanks to solution polishing, which
    # can fail silently (osqp#790), so the test asks for less than it usually gets
    "qp-osqp": (1e-9, 1e-5),
    # first-order ADMM on the conic form: accuracy depends on conditioning
    "qp-scs": (1e-9, 1e-5),
    # qpsolvers hands ECOS the epigraph SOCP t ≥ ½xᵀPx + qᵀx (a rotated cone with a
    # unit constant): x is only accurate to about √gap and stationarity stalls near
    # 1e-6 whatever the tolerance
    "qp-ecos": (1e-9, 1e-4),
    # ProxQP's stopping test does not bound complementarity itself: ≈1e-8 at eps 1e-9
    "qp-proxqp": (1e-9, 1e-7),
}


def accuracy(method: str) -> tuple[float, float]:
    return ACCURACY.get(method, TIGHT)


def require(method: str) -> None:
    """Skip (visibly, naming the module) when a backend of ``method`` is missing."""
    for module in get_method(method).requires:
        pytest.importorskip(module, reason=f"{method} needs the module {module!r}")


def exact_answer(problem: ContactProblem) -> tuple[np.ndarray, np.ndarray]:
    """``(u, λ)`` by enumerating active sets of the small dense problem."""
    K, N = problem.K.toarray(), problem.N.toarray()
    m, n = N.shape
    scale = max(1.0, np.abs(problem.d).max())
    for size in range(m + 1):
        for active in map(list, itertools.combinations(range(m), size)):
            kkt = np.block([[K, N[active].T], [N[active], np.zeros((size, size))]])
            x = np.linalg.solve(kkt, np.concatenate([problem.f, problem.d[active]]))
            u, lam = x[:n], np.zeros(m)
            lam[active] = x[n:]
            dual_ok = lam.min() >= -1e-12 * max(1.0, lam.max())
            if dual_ok and (N @ u - problem.d).max() <= 1e-12 * scale:
                return u, lam
    raise AssertionError("no active set satisfies the KKT conditions")


def rel_dist(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def case(n: int, m: int, seed: int) -> ContactProblem:
    return random_problem(n=n, m=m, seed=seed)


def test_reference_cases_mix_active_and_inactive_constraints():
    active = [exact_answer(case(*c))[1] > 0 for c in CONTACT_CASES]
    assert any(a.any() and not a.all() for a in active)
    assert any(a.all() for a in active)
    assert not exact_answer(case(*NO_CONTACT_CASE))[1].any()


# --- accuracy, certificate, sign ---------------------------------------------------------


@pytest.mark.parametrize("n, m, seed", CONTACT_CASES)
@pytest.mark.parametrize("method", METHODS)
def test_matches_exact_answer(method, n, m, seed, capfd):
    require(method)
    tol, bound = accuracy(method)
    problem = case(n, m, seed)
    u, lam = exact_answer(problem)
    sol = solve(problem, method, tol=tol)
    cert = certificate(problem, sol)
    # the backend's own claim (judge() may then downgrade it to "inaccurate" when the
    # certificate misses ACCEPT_FACTOR × tol: interior points leave forces of order tol
    # on inactive candidates, which the natural residual counts relative to ‖λ‖∞)
    claimed = sol.own_status
    assert sol.status in ("converged", "inaccurate"), sol.message
    if method not in ACCURACY:
        assert claimed == "converged", sol.message
    if sol.status == "converged":  # a claim that survived judge() is backed by the certificate
        assert cert.worst()[1] <= registry.ACCEPT_FACTOR * tol
    assert cert.worst()[1] <= bound, cert
    assert rel_dist(sol.u, u) <= bound
    assert rel_dist(sol.lam, lam) <= bound
    assert sol.build_time > 0 and sol.solve_time > 0
    prefix = "cvxpy/" if method == "cvxpy" else qp.BACKEND_BY_NAME[method[3:]].label + ":"
    assert sol.extras["raw_status"] and sol.message.startswith(prefix)
    out, err = capfd.readouterr()
    assert out == "" and err == "", "the library must not print"


@pytest.mark.parametrize("method", METHODS)
def test_sign_convention(method):
    """λ ≥ 0 multiplies Nu ≤ d: K u − f + Nᵀλ = 0, and λ > 0 where contact is active."""
    require(method)
    tol, bound = accuracy(method)
    problem = case(12, 5, 3)
    _, exact_lam = exact_answer(problem)
    sol = solve(problem, method, tol=tol)
    force = np.abs(sol.lam).max()
    assert force > 0
    assert sol.lam.min() >= -bound * force
    residual = problem.K @ sol.u - problem.f + problem.N.T @ sol.lam
    scale = np.abs(problem.f).max() + np.abs(problem.N.T @ sol.lam).max()
    assert np.abs(residual).max() <= bound * scale
    assert np.all(sol.lam[exact_lam > 0] > 0)


CVXPY_SOLVERS = ["CLARABEL", "OSQP", "SCS", "ECOS", "PIQP", "PROXQP", "DAQP", "HIGHS"]


@pytest.mark.parametrize("solver", CVXPY_SOLVERS)
def test_cvxpy_dual_sign_for_each_solver(solver):
    """cvxpy's dual_value of ``N @ x <= d`` is λ ≥ 0 whichever solver computes it."""
    pytest.importorskip("cvxpy")
    if solver not in cvxpy_method.qp_solvers():
        pytest.skip(f"cvxpy solver {solver} is not installed")
    problem = case(12, 5, 3)
    u, lam = exact_answer(problem)
    sol = solve(problem, "cvxpy", tol=1e-9, solver=solver)
    assert sol.extras["solver"] == solver
    # a sign check, not an accuracy test: ECOS (SOCP form) and first-order solvers
    # get within 1e-4 here, a flipped sign would be off by O(1)
    assert rel_dist(sol.lam, lam) <= 1e-4
    assert rel_dist(sol.u, u) <= 1e-4
    assert np.all(sol.lam[lam > 0] > 0)


@pytest.mark.parametrize("method", METHODS)
def test_no_contact(method):
    """When nothing touches, λ = 0 up to the tolerance and u is the free solution."""
    require(method)
    tol, bound = accuracy(method)
    problem = case(*NO_CONTACT_CASE)
    u, _ = exact_answer(problem)
    sol = solve(problem, method, tol=tol)
    assert sol.status in ("converged", "inaccurate"), sol.message
    assert rel_dist(sol.u, u) <= bound
    assert np.abs(sol.lam).max() <= bound * np.abs(problem.f).max()


def test_certificate_of_exact_no_contact_answer_with_roundoff_forces():
    """Force residuals are floored at FORCE_FLOOR·‖f‖∞, so round-off forces do not count."""
    problem = case(*NO_CONTACT_CASE)
    u, lam = exact_answer(problem)
    sol = ContactSolution("exact", u, lam + 1e-12, "converged")
    assert certificate(problem, sol).worst()[1] <= 1e-6


# --- options, tolerances, status mapping ---------------------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_unknown_option_is_refused(method):
    """Checked before the backend is loaded, so it holds for uninstalled backends too."""
    function = get_method(method).function
    with pytest.raises(InputError, match="not_an_option") as info:
        function(case(8, 3, 0), not_an_option=1)
    assert "accepted options" in str(info.value)
    for name in get_method(method).options:
        assert name in str(info.value)


def test_backend_options_pass_through():
    require("qp-osqp")
    problem = case(12, 5, 1)
    sol = solve(problem, "qp-osqp", tol=1e-9, polishing=False, eps_abs=1e-10, eps_rel=1e-10,
                max_iter=100_000)
    assert sol.extras["polish_status"] == 0  # 0: polishing not performed
    assert sol.extras["raw_status"] == "solved"


def test_tol_none_leaves_backend_defaults_untouched():
    for backend in qp.BACKENDS:
        assert backend.settings(None, None) == {}
        if backend.tolerance is not None:
            assert backend.settings(1e-6, None)
    assert qp.BACKEND_BY_NAME["osqp"].settings(1e-7, 50) == {
        "eps_abs": 1e-7, "eps_rel": 1e-7, "eps_prim_inf": 1e-7, "polishing": True, "max_iter": 50}
    assert qp.BACKEND_BY_NAME["gurobi"].settings(1e-12, None)["FeasibilityTol"] == 1e-9


@pytest.mark.parametrize("backend, raw, status", [
    ("osqp", "solved", "converged"), ("osqp", "solved inaccurate", "inaccurate"),
    ("osqp", "maximum iterations reached", "max_iter"), ("osqp", "primal infeasible", "infeasible"),
    ("osqp", "run time limit reached", "failed"),
    ("clarabel", "Solved", "converged"), ("clarabel", "AlmostSolved", "inaccurate"),
    ("clarabel", "MaxIterations", "max_iter"), ("clarabel", "NumericalError", "failed"),
    ("proxqp", "PROXQP_MAX_ITER_REACHED", "max_iter"), ("piqp", "PIQP_NUMERICS", "failed"),
    ("scs", "solved", "converged"), ("scs", "solved (inaccurate - reached max_iters)", "max_iter"),
    ("scs", "solved (inaccurate - reached time_limit_secs)", "inaccurate"),
    ("scs", "infeasible", "infeasible"), ("scs", "unbounded", "failed"),
    ("ecos", "OPTIMAL", "converged"), ("ecos", "OPTIMAL_INACC", "inaccurate"),
    ("ecos", "MAXIT", "max_iter"), ("ecos", "NUMERICS", "failed"),
    ("quadprog", "no solution", "infeasible"), ("cvxopt", "unknown", "failed"),
    ("gurobi", "SUBOPTIMAL", "inaccurate"), ("highs", "kOptimal", "converged"),
])
def test_status_mapping(backend, raw, status):
    assert qp.BACKEND_BY_NAME[backend].status(raw) == status


TRUNCATED = {"qp-osqp": "max_iter", "qp-clarabel": "max_iter", "qp-piqp": "max_iter",
             "qp-proxqp": "max_iter", "qp-ecos": "max_iter", "qp-scs": "max_iter",
             # qpsolvers does not pass HiGHS's model status or DAQP's exit flag on
             "qp-highs": "failed", "qp-daqp": "failed", "cvxpy": "max_iter"}


@pytest.mark.parametrize("method", sorted(TRUNCATED))
def test_truncated_run_is_not_converged(method):
    require(method)
    sol = solve(case(12, 5, 1), method, max_iter=1, polish=False)  # the backend's own answer
    assert sol.status == TRUNCATED[method], sol.message
    assert sol.extras["raw_status"]


def test_cvxpy_truncated_first_order_run():
    require("cvxpy")
    sol = solve(case(12, 5, 1), "cvxpy", max_iter=1, solver="OSQP", polish=False)
    assert sol.status == "max_iter" and sol.extras["raw_status"] == "user_limit"


@pytest.mark.parametrize("method", ["qp-osqp", "qp-clarabel", "cvxpy"])
def test_polish_by_default_says_which_answer_it_returns(method):
    """Polished by default: a truncated run's answer either becomes the polished one, and the
    message says so, or stays the backend's, not converged."""
    require(method)
    sol = solve(case(12, 5, 1), method, max_iter=1)
    record = sol.extras["polish"]
    assert record["raw_status"] == TRUNCATED[method]
    if record["kept"]:
        assert "the polished answer" in sol.message
        assert sol.status == "converged" and record["polished"] != record["raw"]
    else:
        assert sol.status == TRUNCATED[method] and "the backend's answer" in sol.message


def test_cvxpy_refuses_unknown_solver():
    require("cvxpy")
    with pytest.raises(InputError, match="CLARABEL") as info:
        solve(case(8, 3, 0), "cvxpy", solver="NO_SUCH_SOLVER")
    assert "NO_SUCH_SOLVER" in str(info.value)


# --- dense guard, errors ---------------------------------------------------------------------


@pytest.mark.parametrize("method", DENSE_METHODS)
def test_dense_backend_refuses_large_problems(method):
    assert get_method(method).dense
    with pytest.raises(InputError, match="max_dense_dofs"):
        get_method(method).function(case(8, 3, 0), max_dense_dofs=5, form="primal")


def big_sparse_problem(n: int) -> ContactProblem:
    m = 2
    return ContactProblem(
        K=sp.identity(n, format="csr"), f=-np.ones(n), N=sp.csr_matrix(
            (-np.ones(m), (np.arange(m), np.arange(m))), shape=(m, n)),
        d=np.full(m, 0.5), weights=np.ones(m), contact_points=np.zeros((m, 2)))


@pytest.mark.parametrize("method", DENSE_METHODS)
def test_dense_guard_default_is_3000_dofs(method):
    with pytest.raises(InputError, match="max_dense_dofs = 3000"):
        get_method(method).function(big_sparse_problem(3001), form="primal")


def test_sparse_backend_accepts_max_dense_dofs_and_ignores_it():
    require("qp-clarabel")
    problem = big_sparse_problem(3001)
    sol = solve(problem, "qp-clarabel", tol=1e-9, max_dense_dofs=5)
    assert sol.status == "converged"  # Clarabel says AlmostSolved at its gap of 1e-14; polished
    np.testing.assert_allclose(sol.u[:2], [-0.5, -0.5], atol=1e-5)  # both candidates touch
    np.testing.assert_allclose(sol.lam, [0.5, 0.5], atol=1e-5)


def test_max_dense_dofs_must_be_a_positive_integer():
    with pytest.raises(InputError, match="max_dense_dofs"):
        get_method("qp-quadprog").function(case(8, 3, 0), max_dense_dofs=0)


def test_backend_exception_becomes_solver_error():
    """quadprog refuses an indefinite K; the error is re-raised ``from`` the backend's."""
    require("qp-quadprog")
    problem = case(8, 3, 0).with_data(K=-sp.identity(8, format="csr"))
    with pytest.raises(SolverError, match="positive definite") as info:
        get_method("qp-quadprog").function(problem)
    assert info.value.__cause__ is not None
