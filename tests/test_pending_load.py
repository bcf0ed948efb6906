"""Load control (signorini.load_control): a target load is matched outside assembly, by one driver.

A scene with a target load P is assembled at a nominal push with the target
``pending``; building it factorises nothing. Load control matches it: by
factorisation (the full active-set system, or the zone kernel), or, for
pdas-amg, with the push as one more unknown of its CG systems
(:class:`signorini.solvers.amg_system.LoadBorder`), never factorised. Every route
must give the same answer for the same load; a method that solves the QP as
it is refuses a pending problem. Work is counted, not timed.
"""

import dataclasses
import importlib.util

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini import load_control
from signorini.certification.comparison import compare
from signorini.certification.kkt import certificate
from signorini.numerics.factor import counting
from signorini.numerics.multigrid import Bordered
from signorini.problem.contact import ContactProblem
from signorini.scenes import build_problem
from signorini.solvers import auto
from signorini.solvers.registry import solve

pytest.importorskip("pyamg", reason="pdas-amg needs pyamg (a default dependency)")

SCENE = "hertz-sphere-3d"  # a target load by default (a traction on the cut, one pushed dof)
PUSHED = {"loading": "displacement"}  # the whole cut pushed: many dofs moving together


def solved(problem, method, **options):
    """Load control and the method, as signorini.solve runs them: (problem solved, solution)."""
    result = signorini.solve(problem, method, **options)
    return result.problem, result.solution


@pytest.fixture(scope="module", params=[{}, PUSHED], ids=["traction", "pushed-cut"])
def pair(request):
    """(pending problem, the same scene matched by factorisation)."""
    with counting() as work:
        pending = build_problem(SCENE, params=request.param)
    assert work.factorisations == 0, "a problem is built without a factorisation"
    return pending, load_control.at_load(pending)


def test_the_target_is_pending_until_matched(pair):
    pending, eager = pair
    assert pending.model.pending and not eager.model.pending
    assert pending.model.push.target == pytest.approx(eager.model.push.target, rel=1e-12)
    matched = load_control.match(pending)
    assert not matched.problem.model.pending and matched.work["factorisations"] >= 1
    assert matched.problem.model.push.scale == pytest.approx(eager.model.push.scale, rel=1e-9)
    assert np.allclose(matched.problem.f, eager.f, rtol=0, atol=1e-9 * np.abs(eager.f).max())
    with pytest.raises(signorini.InputError, match="no target load to match"):
        load_control.match(matched.problem)


def test_pdas_amg_matches_the_load_without_a_factorisation(pair):
    pending, eager = pair
    reference = solve(eager, "pdas")
    with counting() as work:
        settled, solution = solved(pending, "pdas-amg")
    assert solution.status == "converged", solution.message
    assert "one more unknown" in solution.message and "load_control" not in solution.work
    assert not settled.model.pending
    # no factorisation of the fine model (its coarse model, if any, is small and counted apart)
    assert work.factorisations <= 1
    assert certificate(settled, solution).worst()[1] <= 1e-9
    assert settled.total_contact_force(solution.lam) == pytest.approx(pending.model.push.target,
                                                                      rel=1e-8)
    assert settled.model.push.scale == pytest.approx(eager.model.push.scale, rel=1e-7)
    agreement = compare(eager, solution, reference)
    assert agreement.lam_rel <= 1e-7 and agreement.misclassified == 0, agreement.as_dict()


def test_any_other_method_gets_the_problem_matched_first(pair):
    pending, eager = pair
    with pytest.raises(signorini.InputError, match="not matched yet"):
        solve(pending, "pdas")  # the method alone solves the QP as it is: it refuses
    settled, solution = solved(pending, "pdas")
    assert solution.status == "converged" and not settled.model.pending
    assert solution.work["load_control"]["factorisations"] >= 1
    assert settled.total_contact_force(solution.lam) == pytest.approx(pending.model.push.target,
                                                                      rel=1e-9)


def test_the_api_reports_the_matched_problem(monkeypatch):
    monkeypatch.setattr(auto, "AMG_FROM_DOFS", 1_000)
    result = signorini.solve(SCENE)
    assert result.status == "converged" and result.method == "pdas-amg"
    assert not result.problem.model.pending
    assert result.total_force == pytest.approx(result.problem.model.params["P"], rel=1e-8)
    assert result.certificate.worst()[1] <= 1e-9


def test_small_models_keep_the_factorised_targeting():
    """auto picks pdas for a small 3D model: load control matches the load by factorisation and
    pdas confirms what it found in one step."""
    result = signorini.solve(SCENE)
    assert result.method == "pdas" and result.iterations == 1
    assert result.solution.work["load_control"]["factorisations"] >= 1


def test_a_pending_problem_is_saved_pending(tmp_path, pair):
    pending, _ = pair
    path = tmp_path / "pending.npz"
    pending.save(path)
    loaded = ContactProblem.load(path)
    assert loaded.model.pending and loaded.model.push.target == pending.model.push.target
    settled, solution = solved(loaded, "pdas")
    assert settled.total_contact_force(solution.lam) == pytest.approx(pending.model.push.target,
                                                                      rel=1e-9)


def test_the_bordered_operator_is_the_bordered_matrix():
    rng = np.random.default_rng(3)
    A = sp.random(30, 30, 0.2, random_state=3)
    K = (A @ A.T + 5 * sp.eye(30)).tocsr()
    g = np.zeros(30)
    g[[2, 7, 11]] = rng.normal(size=3)
    full = sp.bmat([[K, -g[:, None]], [-g[None, :], np.array([[4.0]])]]).toarray()
    y = rng.normal(size=31)
    assert np.allclose(Bordered(K, g, 4.0) @ y, full @ y)


@pytest.mark.skipif(importlib.util.find_spec("petsc4py") is None,
                    reason="the petsc backend of pdas-amg needs petsc4py (extra 'petsc')")
def test_both_multigrids_match_the_load(pair):
    pending, eager = pair
    first = solved(pending, "pdas-amg", amg="petsc")[1]
    second = solved(pending, "pdas-amg", amg="pyamg")[1]
    assert first.status == second.status == "converged"
    assert compare(eager, first, second).lam_rel <= 1e-7


def test_the_push_as_an_unknown_costs_few_cg_iterations(pair):
    """The bordered system is preconditioned by the same hierarchy and the border's diagonal: the
    CG iterations stay close to those of the same problem with the push given (counted, not
    timed; measured at 6.9k dofs: 150 against 120 or so)."""
    pending, _ = pair
    settled, targeted = solved(pending, "pdas-amg")
    given = solve(settled, "pdas-amg")
    assert targeted.status == given.status == "converged"
    assert targeted.extras["cg_iterations"] <= 1.5 * given.extras["cg_iterations"] + 30


def test_a_push_pdas_amg_cannot_carry_is_matched_before_its_bound_form(pair):
    """When the push also moves contact candidates (d₁ ≠ 0) there is no border: load control
    matches the load by factorisation first and pdas-amg solves that problem, not the nominal
    one; alone, pdas-amg refuses the pending problem."""
    pending, _ = pair
    d1 = np.full(pending.m, 1e-3 * np.abs(pending.model.push.d0).max())
    moved = pending.with_data(push=dataclasses.replace(pending.model.push, d1=d1),
                              d=pending.model.push.d0 + pending.model.push.scale * d1)
    assert moved.model.pending
    with pytest.raises(signorini.InputError, match="not matched yet"):
        solve(moved, "pdas-amg")
    (ours_problem, ours), (their_problem, reference) = (solved(moved, "pdas-amg"),
                                                        solved(moved, "pdas"))
    assert ours.status == reference.status == "converged"
    assert ours_problem.model.push.scale == pytest.approx(their_problem.model.push.scale, rel=1e-9)
    assert compare(their_problem, ours, reference).lam_rel <= 1e-7
