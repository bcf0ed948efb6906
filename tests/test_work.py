"""The work of an everyday solve, counted (factorisations and back-solves), not timed (issue 16)."""

from __future__ import annotations

import pytest

import signorini
from signorini.numerics.factor import COUNTS


@pytest.mark.parametrize("scene", ["hertz-cylinder", "hertz-sphere"])
def test_the_default_solve_costs_at_most_three_factorisations(scene):
    before = dict(COUNTS)
    result = signorini.solve(scene)  # build (load targeting), pdas, certificate, Hertz comparison
    assert result.converged
    result.to_dict()
    factorisations = COUNTS["factorisations"] - before["factorisations"]
    assert factorisations <= 3, f"{factorisations} factorisations"
    # load targeting starts from the analytic zone and pdas from its answer: one step each
    assert result.iterations == 1


def test_a_cold_pdas_still_iterates():
    problem = signorini.build_problem("hertz-cylinder").with_data()  # no warm start
    result = signorini.solve(problem)
    assert result.converged and result.iterations > 1
