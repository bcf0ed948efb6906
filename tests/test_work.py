"""The work of an everyday solve, counted (factorisations and back-solves), not timed."""

from __future__ import annotations

import pytest

import signorini
from signorini.numerics.factor import counting


@pytest.mark.parametrize("scene", ["hertz-cylinder", "hertz-sphere"])
def test_the_default_solve_factorises_only_in_load_control(scene):
    with counting() as work:
        result = signorini.solve(scene)  # build (load targeting), pdas, certificate, Hertz comparison
        assert result.converged
        result.to_dict()
    factorisations = work.factorisations
    # load control starts from the analytic zone (one step, or two when the zone's edge node is
    # off), auto's pdas from its answer on its last factorisation, the certificate on the method's
    assert result.iterations == 1
    steps = result.solution.work
    assert steps["load_control"]["steps"] <= 2 and steps["method"]["steps"] == 1
    assert "factorisations" not in steps["method"]
    assert factorisations == steps["load_control"]["factorisations"] <= 2, f"{factorisations}"


def test_a_named_method_starts_cold_and_reports_its_own_steps():
    """pdas named by the caller is not handed what load control found: its steps are its own."""
    result = signorini.solve(signorini.build_problem("hertz-cylinder"), "pdas")
    assert result.converged and result.iterations >= 2
    assert result.solution.work["method"]["steps"] == result.iterations
    assert result.solution.work["load_control"]["steps"] >= 1
    again = signorini.solve(result.problem, "pdas", warm_start=result)  # explicitly warm
    assert again.converged and again.iterations == 1
    assert abs(again.total_force - result.total_force) <= 1e-12 * abs(result.total_force)


def test_a_warm_start_is_refused_by_a_method_that_cannot_use_one():
    result = signorini.solve("block", "pdas")
    with pytest.raises(signorini.InputError, match="takes no warm start"):
        signorini.solve(result.problem, "uzawa", warm_start=result)


def test_a_prediction_from_a_coarser_model_reports_its_work():
    """pdas-amg's first active set comes from a coarser model of the scene, solved for it: that
    stage's factorisations are the result's too."""
    pytest.importorskip("pyamg", reason="pdas-amg needs pyamg")
    result = signorini.solve("hertz-sphere-3d", "pdas-amg",
                             params={"delta": 0.0025, "refine": 1, "n_contact": 8})
    assert result.converged and result.solution.extras["first_active"] == "given"
    assert result.solution.work["prediction"]["factorisations"] >= 1
    assert "factorisations" not in result.solution.work["method"]
