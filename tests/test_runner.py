"""The one study runner: typed rows, named reference policies, fresh worker processes."""

import textwrap

import numpy as np
import pytest

from signorini.scenes import build_problem
from signorini.solvers.registry import REGISTRY, Method, get_method, given
from signorini.studies import suite
from signorini.studies.problems import REFERENCE_POLICIES, exact_attempt, trusted
from signorini.studies.runner import MEASURES, Row, Task, run_task, run_tasks

TINY_BLOCK = {"nx": 4, "ny": 4}
BLOCK = {"kind": "scene", "scene": "block", "params": TINY_BLOCK}


def test_the_reference_policies_are_named_and_unknown_ones_are_refused():
    assert set(REFERENCE_POLICIES) >= {"pdas", "nested", "force-controlled-exact", "none"}
    with pytest.raises(ValueError, match="unknown reference policy 'newton'"):
        Task("test", "block", 0, BLOCK, "pdas", reference={"kind": "newton"})
    with pytest.raises(ValueError, match="unknown measure 'speed'"):
        Task("test", "block", 0, BLOCK, "pdas", measure=("speed",))
    assert {"factorisation", "exact", "kkt", "times"} <= set(MEASURES)


def test_a_policy_without_an_exact_answer_compares_nothing():
    row = run_task(Task("test", "block", 0, BLOCK, "pdas", reference={"kind": "none"},
                        measure=("reference", "lam")))
    assert row["status"] == "converged" and "lam_rel" not in row and "misclassified" not in row
    assert row["reference"]["pressure_max_rel"] < 1e-10  # the block's uniform pressure
    assert len(row["lam"]) == row["candidates"]
    assert set(row) <= set(Row.__annotations__)


def test_a_kept_exact_answer_is_stored_once_and_read_back(tmp_path):
    problem = build_problem("block", params=TINY_BLOCK)
    keep = tmp_path / "block.model.reference_name.npz"
    spec = {"kind": "nested", "tol": 1e-9, "keep": str(keep)}
    first = trusted(exact_attempt(problem, spec))
    assert first is not None and keep.exists()
    again = exact_attempt(problem, spec)
    assert "read from" in again.message and np.array_equal(again.lam, first.lam)
    assert trusted(exact_attempt(problem, {"kind": "none"})) is None


@pytest.mark.slow
def test_fresh_tasks_get_a_process_each_and_the_others_share_one(tmp_path):
    whoami = tmp_path / "whoami.py"
    whoami.write_text(textwrap.dedent("""
        import os
        from signorini.solvers.registry import solve as package_solve
        def solve(problem, *, tol=None, max_iter=None, **options):
            solution = package_solve(problem, "pdas", tol=tol)
            solution.message = str(os.getpid())
            return solution
    """))
    method = f"{whoami}:solve"

    def task(fresh):
        return Task("test", "block", 0, BLOCK, method, tol=1e-9, fresh=fresh,
                    measure=("factorisation", "times"))

    shared = run_tasks([task(False), task(False)], time_limit=60)
    fresh = run_tasks([task(True), task(True)], time_limit=60)
    assert shared[0]["message"] == shared[1]["message"]
    assert fresh[0]["message"] != fresh[1]["message"]
    for row in fresh:
        assert row["status"] == "converged" and row["factor_s"] > 0
        assert row["ratio_to_factor"] == pytest.approx(row["method_s"] / row["factor_s"])


def test_the_suite_runs_in_a_worker_and_in_process_alike():
    cases = tuple(c for c in suite.DEFAULT_CASES if c.name == "block")
    isolated = suite.run_suite(cases, ["pdas", "uzawa"])
    here = suite.run_suite(cases, ["pdas", "uzawa"], isolate=False)
    assert isolated.passed and here.passed
    assert [c.name for c in isolated.checks] == [c.name for c in here.checks]
    for mine, theirs in zip(isolated.checks, here.checks):  # equal up to threaded round-off
        assert mine.value == pytest.approx(theirs.value, rel=1e-6, abs=1e-12), mine.name
    row = isolated.runs[0]
    assert tuple(row) == suite.RUN_COLUMNS and row["vs_reference"]["misclassified"] == 0
    assert isolated.results[0].reference.status == "converged"
    np.testing.assert_allclose(isolated.results[0].solutions["pdas@1e-09"].lam,
                               here.results[0].solutions["pdas@1e-09"].lam, rtol=1e-10)
    # pdas@1e-09 is the reference's own method: it is run and reported, never checked against itself
    names = [c.name for c in isolated.checks]
    assert not [n for n in names if n.startswith(suite.REFERENCE_LABEL)], names
    assert "uzawa@1e-09 converged: λ agrees with pdas" in names


def test_a_method_known_here_only_keeps_the_suite_in_this_process():
    def pdas_again(problem, *, tol=None, max_iter=None, **options):
        return get_method("pdas").function(problem, tol=tol, max_iter=max_iter, **options)

    mine = Method(name="test-pdas-here", function=pdas_again, summary="pdas, known here",
                  family="user")
    assert not suite.portable(mine) and suite.portable(get_method("pdas"))
    cases = tuple(c for c in suite.DEFAULT_CASES if c.name == "block")
    with given({mine.name: mine}):  # known by its name in this block only
        result = suite.run_suite(cases, ["test-pdas-here"])
    assert mine.name not in REGISTRY
    assert result.passed and result.runs[0]["status"] == "converged"
    answer = result.results[0].solutions["test-pdas-here@1e-09"]
    np.testing.assert_allclose(answer.lam, result.results[0].reference.lam, rtol=1e-10)
