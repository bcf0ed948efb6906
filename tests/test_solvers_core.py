"""The exact solver (PDAS), the paper's Uzawa iteration, the registry and the dense LCP helper."""

import itertools

import numpy as np
import pytest

import signorini
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.certification.kkt import certificate
from signorini.numerics.lcp import solve_lcp
from signorini.scenes import build_problem
from signorini.solvers import pdas, registry


@pytest.fixture(scope="module")
def block():
    return signorini.at_load(build_problem("block", params={"nx": 6, "ny": 6}))


@pytest.fixture(scope="module")
def hertz():
    return signorini.at_load(build_problem("hertz-cylinder", params={"n_contact": 20}))


@pytest.fixture(scope="module", params=["block", "hertz"])
def scene(request, block, hertz):
    return {"block": block, "hertz": hertz}[request.param]


@pytest.fixture(scope="module")
def exact(scene):
    solution = registry.solve(scene, "pdas", tol=1e-9)
    assert solution.status == "converged", solution.message
    return solution


def wrapped_pdas(problem, *, tol=None, max_iter=None, **options):
    """A user-defined solver: PDAS under another name."""
    solution = pdas.pdas(problem, tol=tol, max_iter=max_iter, **options)
    solution.extras["wrapped"] = True
    return solution


def not_a_solver():  # pragma: no cover - never called by a passing test
    raise AssertionError("the registry must pass the problem and tol")


# --- PDAS and Uzawa agree ----------------------------------------------------------------------


def test_pdas_satisfies_kkt_to_round_off(scene, exact):
    cert = certificate(scene, exact)
    assert cert.worst()[1] < 1e-10, cert
    assert exact.iterations >= 1
    assert exact.method == "pdas"


def test_uzawa_agrees_with_pdas(scene, exact):
    uzawa = registry.solve(scene, "uzawa", tol=1e-9)
    assert uzawa.status == "converged", uzawa.message
    comparison = compare(scene, exact, uzawa)
    assert comparison.lam_rel < 1e-6
    assert comparison.u_rel < 1e-6
    assert comparison.misclassified == 0
    np.testing.assert_array_equal(exact.lam > 0, uzawa.lam > 0)


def test_uzawa_converges_at_step_fraction_095(scene, exact):
    uzawa = registry.solve(scene, "uzawa", tol=1e-9, step_fraction=0.95)
    assert uzawa.status == "converged", uzawa.message
    assert uzawa.extras["rho_over_bound"] == pytest.approx(0.95)
    assert compare(scene, exact, uzawa).lam_rel < 1e-6


def test_uzawa_beyond_the_step_bound_does_not_converge(block):
    uzawa = registry.solve(block, "uzawa", tol=1e-9, step_fraction=1.25, max_iter=3000)
    assert uzawa.status in ("diverged", "max_iter")
    assert uzawa.status != "converged"
    assert uzawa.extras["rho_over_bound"] == pytest.approx(1.25)
    assert "step_fraction" in uzawa.message


def test_uzawa_step_bound_is_the_largest_eigenvalue_of_W(block):
    """λ_max(W) of the QP in its own units (W = N K⁻¹ Nᵀ, length per force)."""
    uzawa = registry.solve(block, "uzawa", tol=1e-6)
    K, _, N, _ = block.qp()
    W = N @ np.linalg.solve(K.toarray(), N.T.toarray())
    largest = np.linalg.eigvalsh(0.5 * (W + W.T))[-1]
    assert uzawa.extras["lambda_max"] == pytest.approx(largest, rel=1e-5)
    assert uzawa.extras["lambda_max"] <= largest * (1 + 1e-12)  # Rayleigh quotient: a lower bound


@pytest.mark.slow
@pytest.mark.parametrize("name", ["block", "hertz"])
def test_uzawa_operators_give_the_same_iterates(name, block, hertz):
    problem = {"block": block, "hertz": hertz}[name]
    backsolve = registry.solve(problem, "uzawa", tol=1e-8, operator="backsolve")
    delassus = registry.solve(problem, "uzawa", tol=1e-8, operator="delassus")
    assert backsolve.extras["operator"] == "backsolve"
    assert delassus.extras["operator"] == "delassus"
    assert backsolve.status == delassus.status == "converged"
    # the same iteration up to round-off, which may move the step where the stopping test passes
    assert abs(backsolve.iterations - delassus.iterations) <= 0.01 * delassus.iterations
    lam_scale = np.max(np.abs(delassus.lam))
    assert np.max(np.abs(backsolve.lam - delassus.lam)) <= 1e-8 * lam_scale  # the tol asked for


def test_pdas_stops_when_the_active_set_repeats(hertz):
    solution = registry.solve(hertz, "pdas", tol=1e-9)
    changes = solution.history["changes"]
    assert changes[-1] == 0
    assert all(c > 0 for c in changes[:-1])
    assert solution.iterations == len(changes) - 1


def test_pdas_warm_started_at_the_answer_stops_at_once(hertz):
    first = registry.solve(hertz, "pdas", tol=1e-9)
    again = registry.solve(hertz, "pdas", tol=1e-9, lam0=first.lam)
    assert again.status == "converged"
    assert again.iterations == 1
    assert compare(hertz, first, again).lam_rel < 1e-10


def test_pdas_max_iter_is_reported_not_converged(hertz):
    solution = registry.solve(hertz, "pdas", tol=1e-9, max_iter=1)
    assert solution.status == "max_iter"


# --- input checks ----------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["pdas", "uzawa"])
def test_unknown_option_is_named(block, method):
    with pytest.raises(InputError, match="no_such_option"):
        registry.solve(block, method, no_such_option=1)


@pytest.mark.parametrize("option, value", [("step_fraction", 0.0), ("step_fraction", -1.0),
                                           ("rho", float("nan")), ("divergence_factor", "x")])
def test_bad_uzawa_option_value_is_named(block, option, value):
    with pytest.raises(InputError, match=option):
        registry.solve(block, "uzawa", **{option: value})


def test_bad_uzawa_operator_is_named(block):
    with pytest.raises(InputError, match="operator"):
        registry.solve(block, "uzawa", operator="cholesky")


def test_bad_pdas_c_is_named(block):
    with pytest.raises(InputError, match="c="):
        registry.solve(block, "pdas", c=-1.0)


@pytest.mark.parametrize("tol", [0.0, 1.0, -1e-8, 2.0, float("nan"), float("inf")])
@pytest.mark.parametrize("method", ["pdas", "uzawa"])
def test_tol_outside_zero_one_raises(block, method, tol):
    with pytest.raises(InputError, match="tol"):
        registry.solve(block, method, tol=tol)


@pytest.mark.parametrize("max_iter", [0, -5, 2.5])
def test_bad_max_iter_raises(block, max_iter):
    with pytest.raises(InputError, match="max_iter"):
        registry.solve(block, "pdas", max_iter=max_iter)


@pytest.mark.parametrize("values", [pytest.param({"tol": "abc"}, id="tol=abc"),
                                    pytest.param({"max_iter": float("nan")}, id="max_iter=nan"),
                                    pytest.param({"max_iter": float("inf")}, id="max_iter=inf")])
def test_non_numeric_tol_or_max_iter_raises_input_error(block, values):
    with pytest.raises(InputError, match=next(iter(values))):
        registry.solve(block, "pdas", **values)


def test_unknown_method_lists_the_known_ones(block):
    with pytest.raises(InputError, match="no-such-method") as info:
        registry.solve(block, "no-such-method")
    message = str(info.value)
    for known in ("pdas", "uzawa"):
        assert known in message


def test_user_method_module_function_is_accepted(block):
    spec = f"{__name__}:wrapped_pdas"
    solution = registry.solve(block, spec, tol=1e-9)
    assert solution.status == "converged"
    assert solution.method == spec
    assert solution.extras["wrapped"] is True
    reference = registry.solve(block, "pdas", tol=1e-9)
    assert compare(block, reference, solution).lam_rel < 1e-14
    assert registry.get_method(spec).family == "user"


def test_user_method_refusing_the_signature_becomes_a_failed_solution(block):
    solution = registry.solve(block, f"{__name__}:not_a_solver", tol=1e-9)
    assert solution.status == "failed"
    assert "TypeError" in solution.message
    assert np.all(np.isnan(solution.lam))


@pytest.mark.parametrize("spec, word", [("no_such_module_xyz:solve", "no_such_module_xyz"),
                                        (f"{__name__}:no_such_function", "no_such_function")])
def test_bad_user_method_raises(block, spec, word):
    with pytest.raises(InputError, match=word):
        registry.solve(block, spec)


def test_registry_lists_pdas_and_uzawa():
    names = [m.name for m in registry.methods()]
    assert names == sorted(names)
    assert {"pdas", "uzawa"} <= set(names)
    assert registry.get_method("pdas").exact
    assert not registry.get_method("uzawa").exact


# --- the dense LCP helper against brute force ------------------------------------------------


def random_lcp(seed, m, condition):
    """An SPD W with eigenvalues over [1, condition] and a random b."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((m, m)))
    W = (q * np.geomspace(1.0, condition, m)) @ q.T
    return 0.5 * (W + W.T), rng.standard_normal(m)


def brute_force_lcp(W, b):
    """Every λ ≥ 0 with Wλ − b ≥ 0 and λ ⟂ Wλ − b, found by trying all 2^m active sets."""
    m = len(b)
    found = []
    for k in range(m + 1):
        for chosen in itertools.combinations(range(m), k):
            A = list(chosen)
            lam = np.zeros(m)
            if A:
                lam[A] = np.linalg.solve(W[np.ix_(A, A)], b[A])
            gap = W @ lam - b
            scale = max(1.0, np.max(np.abs(b)))
            if lam.min() >= -1e-10 * scale and gap.min() >= -1e-10 * scale:
                found.append(lam)
    return found


@pytest.mark.parametrize("condition", [1.0, 10.0, 100.0])
@pytest.mark.parametrize("m", [1, 2, 3, 5, 7])
def test_solve_lcp_matches_brute_force(m, condition):
    for seed in range(8):
        W, b = random_lcp(seed, m, condition)
        lam, iterations = solve_lcp(W, b)
        solutions = brute_force_lcp(W, b)
        assert solutions, "an SPD LCP always has a solution"
        # W SPD: the solution is unique (every candidate found is the same vector)
        for other in solutions[1:]:
            np.testing.assert_allclose(other, solutions[0], atol=1e-8)
        np.testing.assert_allclose(lam, solutions[0], rtol=1e-10, atol=1e-12 * np.abs(b).max())
        assert np.all(lam >= 0)
        # PDAS never visits an active set twice (it finishes by pivoting when it would): at most
        # 2^m sets, and at least one step unless the answer is λ = 0 from the start
        assert (0 if np.all(solutions[0] == 0) else 1) <= iterations <= 2 ** m


def test_solve_lcp_warm_start_at_the_answer():
    W, b = random_lcp(3, 6, 30.0)
    lam, _ = solve_lcp(W, b)
    again, iterations = solve_lcp(W, b, lam0=lam)
    assert iterations == 1
    np.testing.assert_allclose(again, lam, rtol=1e-12, atol=1e-14)


def test_solve_lcp_converges_on_an_ill_conditioned_spd_lcp():
    W, b = random_lcp(44, 3, 1e4)
    lam, _ = solve_lcp(W, b, max_iter=1000)
    (expected,) = brute_force_lcp(W, b)
    np.testing.assert_allclose(lam, expected, rtol=1e-8)


def test_uzawa_reads_its_step_in_the_problem_s_own_units():
    """A step ρ given in the units of a QP from its data is the same step in any units: the
    iterates, the status and the reported ρ do not depend on the unit of force."""
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    runs = []
    for unit in (1.0, 1e6):  # forces in N, or in MN (K and f scale, d does not)
        problem = signorini.ContactProblem.from_qp(K=K / unit, f=np.array([2.0, 1.0]) / unit,
                                                   N=np.eye(2), d=np.array([0.5, 1.0]))
        runs.append(signorini.solve(problem, "uzawa", tol=1e-10, rho=0.5 / unit, lam0=np.zeros(2)))
    assert [r.status for r in runs] == ["converged", "converged"]
    assert runs[0].iterations == runs[1].iterations
    np.testing.assert_allclose(runs[1].force * 1e6, runs[0].force, rtol=1e-9)
    assert runs[1].solution.extras["rho"] == pytest.approx(0.5e-6)
    assert runs[0].solution.extras["lambda_max"] == pytest.approx(1.0, rel=1e-6)
    assert runs[1].solution.extras["lambda_max"] == pytest.approx(1e6, rel=1e-6)
