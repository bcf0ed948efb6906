"""A method that cannot proceed returns a status; a request out of range is an InputError naming it.

Rows of N that are zero, repeated or dependent, an infeasible QP and an indefinite K reach the
methods and the certificate: every method ends with a status (the certificate's forward error
is then unknown, not an exception). ``max_iter`` beyond what a backend's counter holds and a
warm start from a problem of another size are refused before any work, naming the argument.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import signorini
from signorini.errors import InputError
from signorini.problem.contact import STATUSES
from signorini.solvers.base import MAX_ITER

K = sp.diags([2.0, 2.0, 2.0]).tocsr()
F = np.ones(3)
#: (label, N, d): constraint rows a method's linear algebra meets as a singular system
ROWS = [("zero row", [[1.0, 0, 0], [0, 0, 0]], [0.1, 1.0]),
        ("repeated", [[1.0, 0, 0], [1.0, 0, 0]], [0.1, 0.1]),
        ("dependent", [[1.0, 0, 0], [0, 1.0, 0], [1.0, 1.0, 0]], [0.1, 0.1, 0.2]),
        ("infeasible", [[1.0, 0, 0], [-1.0, 0, 0]], [-1.0, -1.0])]


@pytest.mark.parametrize("method", ["uzawa", "uzawa-nesterov", "pdas"])
@pytest.mark.parametrize("label, N, d", ROWS, ids=[r[0] for r in ROWS])
def test_singular_constraint_rows_end_with_a_status(method, label, N, d):
    problem = signorini.ContactProblem.from_qp(K, F, np.array(N), np.array(d))
    result = signorini.solve(problem, method, max_iter=2000)
    assert result.status in STATUSES
    if label == "infeasible":
        assert result.status != "converged"


def test_an_indefinite_k_ends_failed_in_a_crosscheck_as_in_a_solve():
    K_indefinite = sp.diags([2.0, -1.0, 2.0]).tocsr()
    problem = signorini.ContactProblem.from_qp(K_indefinite, F, np.eye(3)[:2], np.full(2, 0.1))
    check = signorini.crosscheck(problem, ["uzawa", "qp-clarabel", "pdas"])
    assert not check.passed
    assert {run.status for run in check.runs} <= set(STATUSES) | {"refused", "not installed"}
    assert signorini.solve(problem, "pdas").status == "failed"


@pytest.mark.parametrize("method", ["qp-osqp", "qp-clarabel", "uzawa"])
@pytest.mark.parametrize("max_iter", [1e20, MAX_ITER + 1, 2 ** 63])
def test_max_iter_beyond_a_backends_counter_names_max_iter(method, max_iter):
    with pytest.raises(InputError, match=f"max_iter must be a positive integer up to {MAX_ITER}"):
        signorini.solve("block", method, max_iter=max_iter)


def test_a_warm_start_from_another_problem_names_warm_start():
    earlier = signorini.solve("block", "pdas")
    with pytest.raises(InputError, match="warm_start: its u has shape"):
        signorini.solve("block", "pdas", params={"nx": 6}, warm_start=earlier)
    with pytest.raises(InputError, match="warm_start must be an earlier Result"):
        signorini.solve("block", "pdas", warm_start=[0.0])


def test_an_unbounded_dual_within_the_step_bound_says_infeasible_not_lower_rho():
    problem = signorini.ContactProblem.from_qp(K, F, np.array(ROWS[3][1]), np.array(ROWS[3][2]))
    result = signorini.solve(problem, "uzawa-nesterov")
    assert result.status == "diverged", result.message
    assert "infeasible" in result.message and "lower rho" not in result.message


def test_a_builtin_methods_failure_names_the_packages_line_not_a_librarys():
    problem = signorini.ContactProblem.from_qp(K, F, np.array(ROWS[1][1]), np.array(ROWS[1][2]))
    result = signorini.solve(problem, "pdas")
    assert result.status == "failed" and "signorini" in result.message.rsplit(" at ", 1)[-1]
