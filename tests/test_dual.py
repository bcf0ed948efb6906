"""Duality support for the tutorials: the two-wheel model, the dual function, recorders, paths, plots."""

import io

import numpy as np
import pytest
from matplotlib.axes import Axes

import signorini
from signorini.errors import InputError
from signorini.kkt import active_set
from signorini.numerics.lcp import delassus
from signorini.scenes import build_problem
from signorini.solvers.registry import solve
from signorini.teaching import figures as plots
from signorini.teaching.dual import (
    DenseDual,
    IterationHistory,
    IterationRecorder,
    dense_dual,
    lagrangian,
    objectives,
    solve_recorded,
    uzawa_path,
)
from signorini.teaching.synthetic import bogie, bogie_compliance, bogie_deflection, random_problem


@pytest.fixture(scope="module")
def touching():
    """Both wheels on the rail: the dual maximiser lies inside the quadrant."""
    return bogie()


@pytest.fixture(scope="module")
def hanging():
    """Wheel 2 in the air: the maximiser lies on the edge λ₂ = 0."""
    return bogie(gaps=(0.0, 2.0))


@pytest.fixture(scope="module")
def hertz():
    return signorini.at_load(build_problem("hertz-cylinder", params={"n_contact": 16, "grading": 0.4}))


@pytest.fixture(scope="module")
def hertz_exact(hertz):
    solution = solve(hertz, "pdas", tol=1e-9)
    assert solution.status == "converged", solution.message
    return solution


def _exact(problem):
    solution = solve(problem, "pdas", tol=1e-9)
    assert solution.status == "converged", solution.message
    return solution


# --- the two-wheel model -------------------------------------------------------------------------


@pytest.mark.parametrize("params", [{}, {"gaps": (0.0, 2.0)}, {"tilt_stiffness": 10.0},
                                    {"half_length": 0.7, "bending_stiffness": 3.0}])
def test_bogie_delassus_matches_the_closed_form_compliance(params):
    problem = bogie(**params)
    W = delassus(problem.N, problem.factor())
    np.testing.assert_allclose(W, bogie_compliance(problem), rtol=1e-12, atol=1e-13 * np.max(W))


def test_bogie_default_is_a_seesaw_and_a_stiff_tilt_is_not():
    assert bogie_compliance(bogie())[0, 1] < 0
    assert bogie_compliance(bogie(tilt_stiffness=10.0))[0, 1] > 0


def test_bogie_contact_states_and_force_balance(touching, hanging):
    both = _exact(touching)
    assert np.all(both.lam > 0)
    np.testing.assert_allclose(touching.gap(both.u), 0.0, atol=1e-12)
    one = _exact(hanging)
    assert one.lam[0] > 0 and one.lam[1] == 0.0
    assert hanging.gap(one.u)[1] > 0.1
    for problem, solution in ((touching, both), (hanging, one)):
        assert problem.total_contact_force(solution.lam) == pytest.approx(
            problem.applied_load(solution.u), rel=1e-12)


@pytest.mark.parametrize("bad", [{"half_length": 0.0}, {"mount_stiffness": -1.0},
                                 {"tilt_stiffness": float("nan")}, {"gaps": (0.0,)},
                                 {"lowering": float("inf")}])
def test_bogie_refuses_bad_parameters(bad):
    with pytest.raises(InputError):
        bogie(**bad)


def test_bogie_deflection_interpolates_the_nodal_values(touching):
    solution = _exact(touching)
    x, w = bogie_deflection(touching, solution.u, samples=201)
    full = touching.expand(solution.u)
    np.testing.assert_allclose(w[[0, 100, 200]], full[[0, 2, 4]], atol=1e-14)
    tilt = np.array([-0.3, 0.3, 0.0, 0.3, 0.3, 0.3])  # a rigid rotation w = 0.3 x
    x, w = bogie_deflection(touching, tilt)
    np.testing.assert_allclose(w, 0.3 * x, atol=1e-14)


# --- the dual function ---------------------------------------------------------------------------


@pytest.mark.parametrize("problem", [bogie(), random_problem(n=9, m=4, seed=3)], ids=["bogie", "random"])
def test_dense_dual_equals_the_dual_objective_and_the_lagrangian(problem):
    dual = dense_dual(problem)
    rng = np.random.default_rng(0)
    lams = rng.uniform(0.0, 1.0, size=(5, problem.m))
    values = dual(lams)
    assert values.shape == (5,)
    for lam, value in zip(lams, values):
        u = problem.displacement_for(lam)
        assert value == pytest.approx(problem.dual_objective(lam), rel=1e-12, abs=1e-12)
        assert value == pytest.approx(lagrangian(problem, u, lam), rel=1e-12, abs=1e-12)
        np.testing.assert_allclose(dual.gradient(lam), problem.N @ u - problem.d, atol=1e-12)
    assert dual(np.zeros(problem.m)) == pytest.approx(
        problem.energy(problem.displacement_for(np.zeros(problem.m))), rel=1e-12)


def test_weak_duality_holds_for_feasible_pairs(touching):
    dual = dense_dual(touching)
    feasible_u = _exact(touching).u
    rng = np.random.default_rng(1)
    for lam in rng.uniform(0.0, 2.0, size=(50, 2)):
        assert dual(lam) <= touching.energy(feasible_u) + 1e-12
    pair = objectives(touching, feasible_u, dual.maximiser())
    assert abs(pair.gap) < 1e-12


@pytest.mark.parametrize("fixture", ["touching", "hanging"])
def test_dual_maximiser_is_pdas_force_and_the_grid_does_not_beat_it(fixture, request):
    problem = request.getfixturevalue(fixture)
    dual = dense_dual(problem)
    star = dual.maximiser()
    np.testing.assert_allclose(star, _exact(problem).lam, rtol=1e-10, atol=1e-12)
    grid = np.stack(np.meshgrid(np.linspace(0, 2 * star.max(), 161),
                                np.linspace(0, 2 * star.max(), 161)), axis=-1)
    assert np.max(dual(grid)) <= dual(star) + 1e-12
    assert np.max(dual(grid)) > dual(star) - 1e-3 * abs(dual(star))


def test_unconstrained_maximiser_leaves_the_quadrant_when_a_wheel_hangs(hanging, touching):
    assert dense_dual(hanging).unconstrained_maximiser()[1] < 0
    np.testing.assert_allclose(dense_dual(touching).unconstrained_maximiser(),
                               dense_dual(touching).maximiser(), rtol=1e-10)


def test_step_bound_and_condition_number(touching):
    dual = dense_dual(touching)
    assert isinstance(dual, DenseDual) and dual.m == 2
    eig = np.linalg.eigvalsh(bogie_compliance(touching))
    assert dual.step_bound == pytest.approx(2 / eig[-1], rel=1e-12)
    assert dual.condition_number == pytest.approx(eig[-1] / eig[0], rel=1e-12)


def test_dense_dual_refuses_large_problems_and_bad_shapes(touching):
    with pytest.raises(InputError, match="max_candidates"):
        dense_dual(touching, max_candidates=1)
    with pytest.raises(InputError):
        dense_dual(touching)(np.zeros(3))


# --- recording iterations ------------------------------------------------------------------------


def test_pdas_history_closes_the_gap_and_ends_feasible(hertz, hertz_exact):
    solution, history = solve_recorded(hertz, "pdas", tol=1e-9)
    assert solution.status == "converged"
    assert isinstance(history, IterationHistory) and len(history) == solution.iterations + 1
    scale = abs(history.primal[-1])
    assert np.all(np.abs(history.gap) <= 1e-12 * scale)  # forces only where gaps are closed
    assert history.primal_infeasibility[-1] < 1e-12 and history.dual_infeasibility[-1] == 0.0
    assert history.primal_infeasibility[0] > 0.1  # starts from the contact-free solution
    assert np.any(history.dual_infeasibility > 0)  # and goes through pulling forces
    assert np.max(history.stationarity) < 1e-10
    np.testing.assert_array_equal(history.active[-1], active_set(hertz, hertz_exact))
    assert history.primal[-1] == pytest.approx(hertz.energy(hertz_exact.u), rel=1e-12)


def test_uzawa_history_is_dual_feasible_monotone_and_closes_the_gap(hertz, hertz_exact):
    solution, history = solve_recorded(hertz, "uzawa", tol=1e-9)
    assert solution.status == "converged"
    assert len(history) == solution.iterations
    assert np.all(history.dual_infeasibility == 0.0)
    assert np.all(np.diff(history.dual) >= -1e-12 * abs(history.dual[-1]))  # ascent, ρ < 2/λ_max
    contact_energy = hertz.energy(hertz_exact.u) - dense_dual(hertz).constant
    assert np.max(np.abs(history.gap[1:50])) > 1e-3 * contact_energy
    assert abs(history.gap[-1]) < 1e-9 * contact_energy
    assert np.max(history.stationarity) < 1e-10
    assert history.multipliers is None  # 51 candidates: above MAX_RECORDED_MULTIPLIERS


def test_dual_values_are_the_dual_function_of_every_iterate(touching):
    solution, history = solve_recorded(touching, "uzawa", tol=1e-10)
    assert history.multipliers is not None and history.multipliers.shape == (len(history), 2)
    expected = [touching.dual_objective(lam) for lam in history.multipliers]
    np.testing.assert_allclose(history.dual, expected, rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(history.active, history.multipliers > 0)


def test_active_set_is_found_sooner_by_pdas(hertz, hertz_exact):
    final = active_set(hertz, hertz_exact)
    _, pdas_history = solve_recorded(hertz, "pdas", tol=1e-9)
    _, uzawa_history = solve_recorded(hertz, "uzawa", tol=1e-9)
    pdas_found = pdas_history.active_set_found_at(final)
    uzawa_found = uzawa_history.active_set_found_at(final)
    assert pdas_found is not None and uzawa_found is not None
    assert pdas_found < uzawa_found


def test_active_set_found_at_reads_the_last_change():
    active = np.array([[0, 0], [1, 0], [1, 1], [1, 0], [1, 0]], dtype=bool)
    history = IterationHistory(
        iteration=np.arange(1, 6), primal=np.zeros(5), dual=np.zeros(5),
        primal_infeasibility=np.zeros(5), dual_infeasibility=np.zeros(5),
        stationarity=np.zeros(5), active=active)
    assert history.active_set_found_at(np.array([True, False])) == 4
    assert history.active_set_found_at(np.array([True, True])) is None
    np.testing.assert_array_equal(history.misclassified(np.array([True, False])), [1, 0, 1, 0, 0])


def test_recorder_plugs_into_the_solvers_directly(touching):
    recorder = IterationRecorder(touching)
    solve(touching, "pdas", tol=1e-9, callback=recorder.pdas_callback)
    solve(touching, "uzawa", tol=1e-9, callback=recorder.uzawa_callback)
    history = recorder.history()
    assert len(history) > 3 and history.multipliers.shape == (len(history), 2)


def test_solve_recorded_refuses_methods_without_iterates(touching):
    with pytest.raises(InputError, match="cannot report its iterates"):
        solve_recorded(touching, "qp-osqp")
    with pytest.raises(InputError, match="callback"):
        solve_recorded(touching, "pdas", callback=print)


# --- Uzawa's path ---------------------------------------------------------------------------------


def test_uzawa_path_converges_below_the_bound(touching):
    star = dense_dual(touching).maximiser()
    path = uzawa_path(touching, step_ratio=0.9, iterations=200)
    assert path.status == "converged"
    np.testing.assert_array_equal(path.multipliers[0], 0.0)
    assert path.distance(star)[-1] < 1e-8
    assert path.step_ratio == pytest.approx(0.9)
    assert path.rho == pytest.approx(0.9 * 2 / np.linalg.eigvalsh(bogie_compliance(touching))[-1])


def test_uzawa_path_with_a_small_step_crawls(touching):
    star = dense_dual(touching).maximiser()
    slow = uzawa_path(touching, step_ratio=0.1, iterations=40)
    good = uzawa_path(touching, step_ratio=0.9, iterations=40)
    assert slow.status == "max_iter"
    assert slow.distance(star)[-1] > 1e3 * good.distance(star)[-1]
    assert np.all(np.diff(slow.distance(star)) < 0)


def test_uzawa_path_beyond_the_bound_grows_without_limit(touching):
    star = dense_dual(touching).maximiser()
    path = uzawa_path(touching, step_ratio=1.5, iterations=40)
    assert path.status != "converged"
    distance = path.distance(star)
    assert distance[-1] > 100 * distance[0]
    assert np.max(path.multipliers[-1]) > 100 * np.max(star)
    assert "≥ 2" in path.message


def test_uzawa_path_beyond_the_bound_stays_bounded_when_w_is_nonnegative():
    problem = bogie(tilt_stiffness=10.0)  # W₁₂ > 0: pushing one wheel up lifts the other
    dual = dense_dual(problem)
    path = uzawa_path(problem, step_ratio=3.0, iterations=300)
    assert path.status != "converged"
    assert np.max(path.multipliers) < 10 * np.max(dual.maximiser())


def test_uzawa_path_steps_are_projections_of_the_trial_points(hanging):
    path = uzawa_path(hanging, step_ratio=0.7, iterations=30)
    assert path.status == "converged"
    assert len(path.trial) == len(path.multipliers) - 1
    np.testing.assert_allclose(path.multipliers[1:], np.maximum(path.trial, 0.0), atol=1e-14)
    assert np.all(path.projected)  # wheel 2's trial force is negative at every step
    np.testing.assert_allclose(path.multipliers[-1], dense_dual(hanging).maximiser(), atol=1e-9)


def test_uzawa_path_refuses_an_ambiguous_step(touching):
    with pytest.raises(InputError):
        uzawa_path(touching)
    with pytest.raises(InputError):
        uzawa_path(touching, rho=0.1, step_ratio=0.5)
    with pytest.raises(InputError):
        uzawa_path(touching, step_ratio=-1.0)


# --- plots ----------------------------------------------------------------------------------------


def _drawn(ax) -> Axes:
    assert isinstance(ax, Axes)
    ax.figure.savefig(io.BytesIO(), format="png")
    return ax


def test_dual_landscape_marks_the_maximiser_and_draws_paths(hanging):
    dual = dense_dual(hanging)
    star = dual.maximiser()
    path = uzawa_path(hanging, step_ratio=0.7, iterations=30)
    ax = plots.dual_landscape(dual, maximiser=star, unconstrained=dual.unconstrained_maximiser(),
                              paths=[("uzawa", path.multipliers)], points=[("pdas", star)])
    plots.projection_steps(path.multipliers, path.trial, count=2, ax=ax)
    _drawn(ax)
    stars = [line for line in ax.get_lines() if line.get_marker() == "*"]
    assert len(stars) == 1
    np.testing.assert_allclose(np.ravel(stars[0].get_xydata()), star)
    lo, hi = ax.get_ylim()
    assert lo < dual.unconstrained_maximiser()[1] < hi  # the default window shows W⁻¹b
    assert len(ax.texts) == 4  # two projected steps, two arrows each


def test_history_plots_draw_on_a_given_axes(hertz, hertz_exact):
    from matplotlib.figure import Figure

    _, pdas_history = solve_recorded(hertz, "pdas", tol=1e-9)
    _, uzawa_history = solve_recorded(hertz, "uzawa", tol=1e-6)
    histories = [("uzawa", uzawa_history), ("pdas", pdas_history)]
    axes = Figure(layout="constrained").subplots(1, 3)
    optimum = hertz.energy(hertz_exact.u)
    point = objectives(hertz, hertz_exact.u, hertz_exact.lam)
    assert plots.objectives_against_iteration(
        histories, optimum=optimum, free_energy=dense_dual(hertz).constant,
        final_points=[("exact", 1, point.primal, point.dual)], ax=axes[0]) is axes[0]
    assert plots.duality_gap_history(histories, scale=1.0, ax=axes[1]) is axes[1]
    assert plots.active_set_history(histories, active_set(hertz, hertz_exact), ax=axes[2]) is axes[2]
    _drawn(axes[0])
    assert axes[0].get_xscale() == "log"


def test_complementarity_by_node_flags_negative_values():
    x = np.linspace(0.0, 1.0, 6)
    force = np.array([1.0, 0.5, 0.0, -0.2, 0.0, 0.0])
    gap = np.array([0.0, 0.0, 0.3, 0.0, 0.6, 1.0])
    ax = _drawn(plots.complementarity_by_node(x, force, gap))
    red = [line for line in ax.get_lines() if line.get_color() == "red" and len(line.get_xdata())]
    assert any(np.allclose(line.get_xdata(), [x[3]]) for line in red)
    clean = _drawn(plots.complementarity_by_node(x, np.abs(force), gap))
    assert not [line for line in clean.get_lines() if line.get_color() == "red"]


def test_nodal_values_and_bogie_shape(touching):
    solution = _exact(touching)
    ax = _drawn(plots.nodal_values(np.arange(4.0), [("a", np.arange(4.0)), ("b", np.ones(4))],
                                   ylabel="λ", highlight=np.array([False, True, False, True]),
                                   highlight_label="ringed"))
    assert "ringed" in [text.get_text() for text in ax.get_legend().get_texts()]
    ax = _drawn(plots.bogie_shape(touching, [("solution", solution.u)]))
    assert ax.get_ylim()[0] < -touching.params["gaps"][1]
