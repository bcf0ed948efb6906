"""The condensed dual against PDAS, and the blocked Delassus operator against a dense one."""

import numpy as np
import pytest

import signorini
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.numerics.factor import factorize
from signorini.numerics.lcp import delassus
from signorini.scenes import build_problem
from signorini.solvers.registry import solve
from synthetic import random_problem


@pytest.mark.parametrize("params", [{"n_contact": 20, "grading": 0.4}, {"candidates": 3.0, "n_contact": 12}])
def test_condensed_equals_pdas_on_hertz(params):
    problem = signorini.at_load(build_problem("hertz-cylinder", params=params))
    exact, condensed = solve(problem, "pdas"), solve(problem, "condensed")
    assert condensed.status == "converged"
    agreement = compare(problem, exact, condensed)
    assert agreement.lam_rel < 1e-8 and agreement.misclassified == 0


@pytest.mark.parametrize("seed", range(5))
def test_condensed_equals_pdas_on_random_problems(seed):
    problem = random_problem(10, 6, seed=seed, condition=100.0)
    agreement = compare(problem, solve(problem, "pdas"), solve(problem, "condensed"))
    assert agreement.lam_rel < 1e-8 and agreement.misclassified == 0


def test_blocked_delassus_matches_the_dense_formula():
    problem = random_problem(12, 7, seed=3)
    K_inv = np.linalg.inv(problem.K.toarray())
    dense = problem.N.toarray() @ K_inv @ problem.N.T.toarray()
    np.testing.assert_allclose(delassus(problem.N, factorize(problem.K), block=3), dense,
                               rtol=1e-10, atol=1e-12)


def test_too_many_candidates_is_refused_with_the_option_named():
    problem = random_problem(10, 6, seed=0)
    with pytest.raises(InputError, match="max_candidates"):
        solve(problem, "condensed", max_candidates=5)
