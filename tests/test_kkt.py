"""KKT certificates, classification of the candidates, comparisons and the registry's judge."""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import load_control
from signorini.certification import kkt
from signorini.certification.comparison import compare
from signorini.certification.inverse import MAX_RELEASED, primal_dual_gap
from signorini.certification.kkt import (
    ACTIVE,
    INACTIVE,
    WEAK,
    WEAK_TOL,
    active_set,
    certificate,
    classify,
    gap_scale,
)
from signorini.numerics.active_set import selection_dofs
from signorini.numerics.factor import counting, factorize
from signorini.problem.contact import ContactProblem, ContactSolution
from signorini.scenes import build as scene_build
from signorini.scenes import build_problem
from signorini.solvers import registry

RESIDUALS = ("primal", "stationarity", "dual_sign", "complementarity", "natural", "duality_gap")


@pytest.fixture(scope="module")
def hertz():
    return signorini.at_load(build_problem("hertz-cylinder", params={"n_contact": 20}))


@pytest.fixture(scope="module")
def exact(hertz):
    solution = registry.solve(hertz, "pdas", tol=1e-9)
    assert solution.status == "converged", solution.message
    return solution


def with_(solution, **changes):
    """A copy of ``solution`` with some fields replaced (arrays copied)."""
    fields = {"u": solution.u.copy(), "lam": solution.lam.copy(), **changes}
    return dataclasses.replace(solution, **fields, history={}, extras={})


def nodes_of(problem, solution):
    gap = problem.gap(solution.u) / gap_scale(problem, solution.u)
    active = np.nonzero(solution.lam > 0)[0]
    inactive = np.nonzero((gap > 1e-9) & (solution.lam == 0))[0]  # open beyond round-off
    assert active.size and inactive.size, "the test needs both active and inactive candidates"
    return active, inactive


def row(problem, i):
    return problem.N[i].toarray().ravel()


def touching_problem():
    """min ½|u|² − fᵀu s.t. −u ≤ d, with f = (−1, 0), d = (½, 0).

    The minimiser is u = (−½, 0), λ = (½, 0): the first constraint is active, the second
    touches (gap 0) with zero force — degenerate, weakly active.
    """
    return ContactProblem(
        K=sp.identity(2, format="csr"), f=np.array([-1.0, 0.0]), N=-sp.identity(2, format="csr"),
        d=np.array([0.5, 0.0]), weights=np.ones(2), contact_points=np.zeros((2, 2)), name="touching")


# --- certificate -----------------------------------------------------------------------------


def test_exact_solution_has_all_residuals_below_1e_10(hertz, exact):
    cert = certificate(hertz, exact)
    for name in RESIDUALS:
        assert 0.0 <= getattr(cert, name) < 1e-10, name
    assert cert.worst()[1] < 1e-10


def test_penetration_raises_primal(hertz, exact):
    active, _ = nodes_of(hertz, exact)
    i = active[len(active) // 2]
    push = 1e-3 * gap_scale(hertz, exact.u)
    bad = with_(exact, u=exact.u + push * row(hertz, i))  # (N u)_i grows by push: penetration
    cert = certificate(hertz, bad)
    assert cert.primal == pytest.approx(1e-3, rel=0.05)
    assert certificate(hertz, exact).primal < 1e-12


def test_negative_force_raises_dual_sign(hertz, exact):
    _, inactive = nodes_of(hertz, exact)
    lam = exact.lam.copy()
    lam[inactive[0]] = -0.1 * lam.max()
    cert = certificate(hertz, with_(exact, lam=lam))
    assert cert.dual_sign == pytest.approx(0.1, rel=1e-12)
    assert certificate(hertz, exact).dual_sign == 0.0


def test_displacement_off_raises_stationarity(hertz, exact):
    rng = np.random.default_rng(0)
    u = exact.u + 1e-6 * np.max(np.abs(exact.u)) * rng.standard_normal(hertz.n)
    cert = certificate(hertz, with_(exact, u=u))
    base = certificate(hertz, exact).stationarity
    assert cert.stationarity > 1e-7
    assert cert.stationarity > 1e3 * base


def test_force_on_an_open_node_raises_complementarity(hertz, exact):
    _, inactive = nodes_of(hertz, exact)
    gap = hertz.gap(exact.u)
    i = inactive[np.argmax(gap[inactive])]
    lam = exact.lam.copy()
    lam[i] = 0.1 * lam.max()
    cert = certificate(hertz, with_(exact, lam=lam))
    expected = 0.1 * gap[i] / gap_scale(hertz, exact.u)
    assert cert.complementarity == pytest.approx(expected, rel=1e-9)
    assert cert.complementarity > 1e-3
    assert cert.natural > 1e-3
    assert certificate(hertz, exact).complementarity < 1e-12


@pytest.mark.parametrize("field, value", [("u", np.nan), ("u", np.inf), ("lam", np.nan),
                                          ("lam", -np.inf)])
def test_non_finite_input_gives_inf(hertz, exact, field, value):
    vector = getattr(exact, field).copy()
    vector[0] = value
    cert = certificate(hertz, with_(exact, **{field: vector}))
    for name in RESIDUALS:
        assert getattr(cert, name) == np.inf, name


def test_certificate_is_unit_free():
    scaled = signorini.at_load(build_problem("block", params={"nx": 4, "ny": 4}))
    raw = signorini.at_load(build_problem("block", params={"nx": 4, "ny": 4, "E": 2.1e11, "delta": 1e-3},
                                          nondimensionalise=False))
    s_scaled = registry.solve(scaled, "pdas", tol=1e-9)
    s_raw = registry.solve(raw, "pdas", tol=1e-9)
    assert s_scaled.status == s_raw.status == "converged"
    # the exact answers have the same (round-off) residuals whatever the units
    assert certificate(scaled, s_scaled).worst()[1] < 1e-10
    assert certificate(raw, s_raw).worst()[1] < 1e-10
    # the same relative perturbation of λ gives the same relative residuals in both units
    for problem, solution in ((scaled, s_scaled), (raw, s_raw)):
        lam = solution.lam * (1 + 1e-4)
        cert = certificate(problem, with_(solution, lam=lam))
        assert cert.stationarity == pytest.approx(1e-4, rel=1e-3)


def test_worst_ignores_a_duality_gap_that_was_not_computed(hertz, exact):
    cert = certificate(hertz, exact, duality_gap=False)
    name, value = cert.worst()
    assert np.isfinite(value) and value < 1e-10, (name, value)


# --- classify and compare --------------------------------------------------------------------


def test_exact_solution_labels_match_forces_and_gaps(hertz, exact):
    labels = classify(hertz, exact)
    assert set(labels) <= {ACTIVE, INACTIVE, WEAK}
    np.testing.assert_array_equal(labels == ACTIVE, exact.lam > 0)
    np.testing.assert_array_equal(active_set(hertz, exact), exact.lam > 0)


def test_solution_compared_with_itself(hertz, exact):
    comparison = compare(hertz, exact, with_(exact))
    assert comparison.u_rel == 0.0
    assert comparison.lam_rel == 0.0
    assert comparison.misclassified == 0
    assert comparison.same_active_set


def test_opening_one_active_node_is_one_misclassification(hertz, exact):
    active, _ = nodes_of(hertz, exact)
    i = active[len(active) // 2]
    lam = exact.lam.copy()
    lam[i] = 0.0
    lift = 1e-2 * gap_scale(hertz, exact.u)
    flipped = with_(exact, u=exact.u - lift * row(hertz, i), lam=lam)  # gap_i = lift
    assert classify(hertz, flipped)[i] == INACTIVE
    comparison = compare(hertz, exact, flipped)
    assert comparison.misclassified == 1
    assert not comparison.same_active_set
    assert comparison.lam_rel > 0 and comparison.u_rel > 0


def test_forcing_one_open_node_is_one_misclassification(hertz, exact):
    _, inactive = nodes_of(hertz, exact)
    gap_n = hertz.gap(exact.u) / gap_scale(hertz, exact.u)
    i = inactive[np.argmin(gap_n[inactive])]  # the open node nearest the contact edge
    assert gap_n[i] < 1.0
    lam = exact.lam.copy()
    lam[i] = lam.max()
    comparison = compare(hertz, exact, with_(exact, lam=lam))
    assert comparison.misclassified == 1


def test_degenerate_node_is_weak_and_not_misclassified():
    problem = touching_problem()
    solution = registry.solve(problem, "pdas", tol=1e-9)
    assert solution.status == "converged"
    np.testing.assert_allclose(solution.u, [-0.5, 0.0], atol=1e-15)
    np.testing.assert_allclose(solution.lam, [0.5, 0.0], atol=1e-15)
    assert certificate(problem, solution).worst()[1] < 1e-14
    assert list(classify(problem, solution)) == [ACTIVE, WEAK]
    # another KKT point to within WEAK_TOL: the degenerate node carries a tiny force
    tiny_force = with_(solution, lam=np.array([0.5, 0.1 * WEAK_TOL]))
    assert list(classify(problem, tiny_force)) == [ACTIVE, WEAK]
    # a candidate that opened the weak node: inactive there, but it is not a misclassification
    opened = with_(solution, u=np.array([-0.5, 1e-2]))
    assert list(classify(problem, opened)) == [ACTIVE, INACTIVE]
    comparison = compare(problem, solution, opened)
    assert comparison.misclassified == 0
    assert comparison.weak == 1
    # forcing it instead is not a misclassification either
    forced = with_(solution, lam=np.array([0.5, 0.25]))
    assert classify(problem, forced)[1] == ACTIVE
    assert compare(problem, solution, forced).misclassified == 0


def test_non_finite_comparison_counts_every_node(hertz, exact):
    broken = with_(exact, lam=np.full(hertz.m, np.nan))
    comparison = compare(hertz, exact, broken)
    assert comparison.lam_rel == np.inf
    assert comparison.misclassified == hertz.m


def test_round_off_force_without_contact_is_not_active():
    # min ½|u|² − fᵀu s.t. u ≤ d with f = (0.5, 0.2), d = (1, 1): u = f is feasible, λ = 0
    problem = ContactProblem(
        K=sp.identity(2, format="csr"), f=np.array([0.5, 0.2]), N=sp.identity(2, format="csr"),
        d=np.array([1.0, 1.0]), weights=np.ones(2), contact_points=np.zeros((2, 2)))
    exact = ContactSolution("exact", np.array([0.5, 0.2]), np.zeros(2), "converged")
    round_off = ContactSolution("round-off", np.array([0.5, 0.2]), np.array([1e-15, 0.0]),
                                "converged")
    assert certificate(problem, round_off).worst()[1] < 1e-9
    assert classify(problem, round_off)[0] != ACTIVE
    assert compare(problem, exact, round_off).misclassified == 0


# --- the registry's judge --------------------------------------------------------------------


def test_judge_downgrades_a_false_claim(hertz, exact):
    bad = with_(exact, lam=exact.lam * 1.01, status="converged", message="backend: solved")
    judged = registry.judge(hertz, bad, 1e-8)
    assert judged.status == "inaccurate"
    assert judged.claimed_status == "converged"
    worst_name, _ = certificate(hertz, with_(exact, lam=exact.lam * 1.01)).worst()
    assert worst_name in judged.message
    assert "backend: solved" in judged.message


def test_judge_names_the_failing_residual(hertz, exact):
    active, _ = nodes_of(hertz, exact)
    i = active[0]
    push = 1e-3 * gap_scale(hertz, exact.u)
    bad = with_(exact, u=exact.u + push * row(hertz, i), status="converged")
    judged = registry.judge(hertz, bad, 1e-6)
    assert judged.status == "inaccurate"
    cert = certificate(hertz, bad)
    name, value = cert.worst()
    assert name in judged.message and name in RESIDUALS


def test_judge_keeps_an_honest_claim(hertz, exact):
    judged = registry.judge(hertz, with_(exact, status="converged"), 1e-9)
    assert judged.status == "converged"
    assert judged.claimed_status == ""


def test_judge_leaves_other_statuses_alone(hertz, exact):
    bad = with_(exact, lam=exact.lam * 2.0, status="max_iter", message="ran out")
    judged = registry.judge(hertz, bad, 1e-8)
    assert judged.status == "max_iter"
    assert judged.message == "ran out"


def test_judge_threshold_follows_tol(hertz, exact):
    # a relative λ error of 1e-7 gives residuals near 1e-7: accepted at 1e-6, refused at 1e-8
    # and by default (signorini.DEFAULT_TOL = 1e-8 without a tolerance)
    nearly = with_(exact, lam=exact.lam * (1 + 1e-7), status="converged")
    worst = certificate(hertz, nearly).worst()[1]
    assert 1e-8 < worst < 1e-6
    assert registry.judge(hertz, with_(nearly), 1e-6).status == "converged"
    assert registry.judge(hertz, with_(nearly), None).status == "inaccurate"
    assert registry.judge(hertz, with_(nearly), 1e-8).status == "inaccurate"


def test_judge_refuses_non_finite_claims(hertz):
    claim = ContactSolution("x", np.full(hertz.n, np.nan), np.zeros(hertz.m), "converged")
    judged = registry.judge(hertz, claim, 1e-3)
    assert judged.status == "inaccurate"


def test_duality_gap_by_conjugate_gradients_equals_the_factorised_one(hertz, exact, monkeypatch):
    """Big problems evaluate rᵀK⁻¹r by CG (no serial factorisation): the same gap."""
    from signorini.problem import contact as problem_module

    rng = np.random.default_rng(0)
    rough = with_(exact, u=exact.u * (1 + 1e-4 * rng.standard_normal(exact.u.size)),
                  lam=exact.lam * 1.001)
    expected = certificate(hertz, rough).duality_gap
    monkeypatch.setattr(problem_module, "ITERATIVE_ENERGY_FROM", 0)
    fresh = hertz.with_data()  # no cached factorisation
    assert fresh.factorises_for_certificates  # a 2D mesh: factorised at any size
    fresh.model = dataclasses.replace(fresh.model, mesh=None)  # a mesh unknown
    assert not fresh.factorises_for_certificates
    by_cg = certificate(fresh, rough).duality_gap
    assert fresh._factor is None
    assert expected > 1e-9 and by_cg == pytest.approx(expected, rel=1e-4)


def test_a_big_2d_problem_factorises_for_its_certificate_instead_of_cg(hertz, exact, monkeypatch):
    """Past ITERATIVE_ENERGY_FROM a 2D mesh is still factorised (little fill), not solved by CG."""
    from signorini.problem import contact as problem_module

    monkeypatch.setattr(problem_module, "ITERATIVE_ENERGY_FROM", 0)
    monkeypatch.setattr("scipy.sparse.linalg.cg", lambda *a, **k: pytest.fail("CG was used"))
    fresh = hertz.with_data()
    with counting() as work:
        cert = certificate(fresh, exact)
    assert fresh._factor is not None and work.factorisations == 1
    assert np.isfinite(cert.duality_gap) and np.isfinite(cert.force_error)


# --- the duality gap on the method's own factorisation ----------------------------------------


@pytest.fixture(scope="module")
def zoned():
    """A cylinder load-targeted on a predicted zone (nested then reuses that factorisation)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(load_control, "ZONE_FROM_DOFS", 0)
        return signorini.at_load(build_problem("hertz-cylinder",
                                               params={"refine": 1, "n_contact": 24, "grading": 0.4}))


def refuse_the_fallback(monkeypatch):
    """Fail on any use of the problem's own way to K⁻¹ (a factorisation, or CG on K)."""
    def refuse(self, r):
        raise AssertionError("the certificate did not reuse the method's factorisation")
    monkeypatch.setattr(ContactProblem, "inverse_energy", refuse)


def spent(step):
    """Factorisations and back-solves ``step()`` performed, and what it returned."""
    with counting() as work:
        out = step()
    return {"factorisations": work.factorisations, "back_solves": work.back_solves}, out


def textbook_gap(problem, u, lam):
    """``λ⁺ᵀ(d − Nu) + ½ rᵀK⁻¹r`` with a factorisation of K of its own."""
    lam = np.maximum(lam, 0.0)
    r = problem.K @ u - problem.f + problem.N.T @ lam
    return float(lam @ problem.gap(u)) + 0.5 * float(r @ factorize(problem.K).solve(r))


def perturbed(solution, size, seed=0):
    rng = np.random.default_rng(seed)
    return (solution.u * (1 + size * rng.standard_normal(solution.u.size)),
            solution.lam * (1 + size * rng.standard_normal(solution.lam.size)))


@pytest.mark.parametrize("method", ["pdas", "nested", "condensed"])
def test_the_certificate_costs_a_few_back_solves_of_the_method_factorisation(zoned, method,
                                                                             monkeypatch):
    """After the solve, the certificate factorises nothing (never CG): for the forward error one
    back-solve per Newton step on a factorisation pinned on the active set and one more per row
    where the pinned set and the active set differ (those columns are kept, so a step costs no
    more), two per step on a plain one offered with its Delassus operator (condensed); and one
    for the duality gap, unless the pinned set is the active set: then the gap's system is the
    first Newton step's with the opposite right-hand side, and its answer is that one's negated."""
    assert zoned.cached_factor is None
    solution = registry.get_method(method).function(zoned)
    assert solution.factor is not None
    if method == "nested":
        assert "coarse" in solution.message or "load targeting" in solution.message
        assert len(solution.factor.fixed) > 0  # the core is pinned
    refuse_the_fallback(monkeypatch)
    fixed = solution.factor.fixed
    differ = np.setxor1d(selection_dofs(zoned.N)[active_set(zoned, solution)], fixed).size
    cost, cert = spent(lambda: certificate(zoned, solution))
    gap = 1 if differ or method == "condensed" else 0
    expected = {"pdas": gap + 2, "nested": gap + differ + 2, "condensed": gap + 4}[method]
    assert cost == {"factorisations": 0, "back_solves": expected}
    assert cert.back_solves == expected - gap  # the forward error's own
    assert cert.worst()[1] < 1e-10
    assert solution.factor is None  # let go once used
    assert spent(lambda: certificate(zoned, solution))[0] == {"factorisations": 0, "back_solves": 0}


def test_the_forward_error_multiplies_by_all_of_k_once_given_k_u(zoned):
    """On a pinned factorisation each Newton step reads only the rows of K x it needs (the
    border's, the active set's): given K u, the one product by the whole K is the second
    step's residual."""
    from signorini.certification.inverse import forward_error

    class Counted(sp.csr_matrix):
        products = 0

        def __matmul__(self, other):
            Counted.products += 1
            return super().__matmul__(other)

    solution = registry.get_method("nested").function(zoned)
    u, lam = solution.u, solution.lam
    found = forward_error(Counted(zoned.K), zoned.f, zoned.N, zoned.d, u, lam,
                          active_set(zoned, solution), solution.factor,
                          kkt.force_scale(zoned, lam, u), Ku=zoned.K @ u)
    assert Counted.products == 1 and found.back_solves == 2 and found.force < 1e-10


def test_the_forward_error_reads_back_the_band_columns_the_zone_solver_kept(zoned, monkeypatch):
    """A zone whose core misses the contact's edge: the band nodes that come into contact are
    rows where the pinned set and the active set differ, and the zone solver has already solved
    their columns; the forward error reads them back instead of solving them again, and says
    what solving them gives."""
    from signorini.numerics.zone import Zone, radial_distance

    exact = registry.solve(zoned, "pdas")
    rho = radial_distance(zoned.contact_points)
    edge = rho[exact.lam > 0].max()
    zone = Zone(core=rho < 0.8 * edge, band=(rho >= 0.8 * edge) & (rho < 1.2 * edge))
    solution = registry.get_method("nested").function(zoned, zone=zone)
    active = selection_dofs(zoned.N)[active_set(zoned, solution)]
    joined = np.setdiff1d(active, solution.factor.fixed)
    assert joined.size > 2 and np.setdiff1d(solution.factor.fixed, active).size == 0
    assert set(joined.tolist()) <= set(solution.factor.kept)
    refuse_the_fallback(monkeypatch)
    cost, cert = spent(lambda: certificate(zoned, solution))
    assert cert.back_solves == 2  # one per Newton step: no column solved again
    again = registry.get_method("nested").function(zoned, zone=zone)
    again.factor.kept.clear()
    cost_again, solved = spent(lambda: certificate(zoned, again))
    assert solved.back_solves == 2 + joined.size
    assert cost["factorisations"] == cost_again["factorisations"] == 0
    assert cost_again["back_solves"] - cost["back_solves"] == joined.size
    assert cert.force_error < 1e-10 and solved.force_error < 1e-10
    assert cert.force_error_floor == pytest.approx(solved.force_error_floor, rel=0.5, abs=1e-14)


@pytest.mark.parametrize("method", ["pdas", "nested"])
def test_a_remembered_back_solve_gives_what_solving_again_gives(zoned, method, monkeypatch):
    """The duality gap's back-solve, answered by the forward error's first one negated, gives the
    certificate that a back-solve of its own gives."""
    def keep(solution):
        return dataclasses.replace(solution, keep_factor=True)

    solution = keep(registry.get_method(method).function(zoned))
    remembered = spent(lambda: kkt._certificate(zoned, solution, True))
    monkeypatch.setattr(kkt.Remembering, "solve", lambda self, rhs: self.factor.solve(rhs))
    solved = spent(lambda: kkt._certificate(zoned, solution, True))
    assert solved[0]["back_solves"] == remembered[0]["back_solves"] + 1
    for name, value in solved[1].residuals().items():
        assert remembered[1].residuals()[name] == pytest.approx(value, rel=1e-12, abs=1e-300), name


def test_the_gap_on_a_pinned_factorisation_is_the_textbook_one_or_tighter(zoned, monkeypatch):
    """Re-optimising the pinned nodes' forces only raises the dual bound, and it stays a bound."""
    exact = registry.get_method("nested").function(zoned)
    factor = exact.factor
    refuse_the_fallback(monkeypatch)
    for size in (1e-3, 1e-6):
        u, lam = perturbed(exact, size)
        cost, pinned = spent(lambda: primal_dual_gap(zoned, u, lam, [factor]))
        textbook = textbook_gap(zoned, u, lam)
        assert cost == {"factorisations": 0, "back_solves": 1}
        assert pinned <= textbook + 1e-12 * abs(textbook)
        assert pinned == pytest.approx(textbook, rel=1e-3)
        assert pinned >= zoned.energy(u) - zoned.energy(exact.u) - 1e-12 * abs(zoned.energy(u))


def test_pinned_nodes_that_would_pull_are_released(zoned, monkeypatch):
    """A factorisation pinned on a wider zone than the answer's (the same K pushed less)."""
    wide = registry.get_method("pdas").function(zoned).factor
    lighter = zoned.pushed(0.9 * zoned.model.push.scale)
    exact = registry.solve(lighter, "pdas")
    assert 0 < len(wide.fixed) - (exact.lam > 0).sum() <= MAX_RELEASED
    refuse_the_fallback(monkeypatch)
    for size in (0.0, 1e-6):
        u, lam = perturbed(exact, size)
        cost, gap = spent(lambda: primal_dual_gap(lighter, u, lam, [wide]))
        assert cost["factorisations"] == 0 and cost["back_solves"] > 1
        textbook = textbook_gap(lighter, u, lam)
        assert gap == pytest.approx(textbook, rel=1e-3, abs=1e-14 * abs(lighter.energy(u)))
        assert gap <= textbook + 1e-12 * abs(lighter.energy(u))


def test_a_factorisation_of_another_matrix_is_not_used(hertz, exact):
    u, lam = perturbed(exact, 1e-4)
    stiffer = factorize(2.0 * hertz.K)
    assert primal_dual_gap(hertz, u, lam, [stiffer]) == pytest.approx(textbook_gap(hertz, u, lam),
                                                                      rel=1e-9)
    # the same matrix under another name (CSC, or a copy) is recognised
    same = factorize(hertz.K)
    same.matrix = sp.csc_matrix(hertz.K, copy=True)
    cost, _ = spent(lambda: primal_dual_gap(hertz.with_data(), u, lam, [same]))
    assert cost == {"factorisations": 0, "back_solves": 1}


def test_an_answer_with_no_factorisation_is_certified_on_one_pinned_factorisation(monkeypatch):
    """An answer given as arrays (no factorisation from its method) with many active rows that
    each bound one dof: the certificate factorises K once with them pinned, a back-solve a Newton
    step and none more for the duality gap, where bordering a plain factorisation costs a
    back-solve a row; both estimates agree."""
    problem = signorini.at_load(build_problem("hertz-cylinder", params={"refine": 1}))
    exact = registry.solve(problem, "pdas", tol=1e-9)
    active = int(active_set(problem, exact).sum())
    assert active >= kkt.PINNED_FROM
    refuse_the_fallback(monkeypatch)
    bare = ContactSolution("given", exact.u, exact.lam, "converged")
    cost, pinned = spent(lambda: certificate(problem, bare))
    assert cost == {"factorisations": 1, "back_solves": 2}
    monkeypatch.undo()
    monkeypatch.setattr(kkt, "PINNED_FROM", problem.m + 1)  # border a plain factorisation instead
    bordered_cost, bordered = spent(lambda: certificate(problem, ContactSolution(
        "given", exact.u, exact.lam, "converged")))
    assert bordered_cost["factorisations"] == 1 and bordered_cost["back_solves"] >= active
    assert pinned.worst()[1] < 1e-10 and bordered.worst()[1] < 1e-10
    assert abs(pinned.force_error - bordered.force_error) < 1e-10


def test_a_kkt_point_of_an_indefinite_k_of_ones_own_is_not_certified_with_many_active_rows():
    """K of one's own with negative curvature on forty dofs, each bounded by an active row: a
    pinned factorisation would see only the positive rest, so the certificate factorises K
    plainly, finds it indefinite, and no claim of convergence stands."""
    n, m = 80, 40
    diagonal = np.full(n, 2.0)
    diagonal[:m] = -1.0
    problem = ContactProblem.from_qp(sp.diags(diagonal).tocsr(), np.zeros(n),
                                     sp.eye(m, n).tocsr(), np.full(m, 0.1))
    u = np.where(np.arange(n) < m, 0.1, 0.0)
    assert m >= kkt.PINNED_FROM
    result = signorini.solve(problem, lambda problem, tol=None, max_iter=None: (u, np.full(m, 0.1)))
    assert result.status == "inaccurate" and np.isinf(result.certificate.duality_gap)
    assert "not positive semidefinite" in result.message
