"""A diagnosis by constraint: an answer that fails the certificate is told which candidates fail
and how (penetration, tension, complementarity, stationarity), with the advice that fits; a
penetrating node is never weakly active; the cross-check gives a table per candidate.
"""

from __future__ import annotations

import json
import textwrap

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.certification.diagnosis import explain, violations
from signorini.certification.comparison import compare
from signorini.certification.kkt import INACTIVE, WEAK, classify

IGNORES = textwrap.dedent("""
    import numpy as np
    import signorini
    from signorini.solvers.pdas import pdas


    def ignores_eight(problem, **options):
        keep = np.arange(problem.m) != 8
        reduced = signorini.ContactProblem.from_qp(problem.K, problem.f, problem.N[keep],
                                                   problem.d[keep])
        answer = pdas(reduced)
        lam = np.zeros(problem.m)
        lam[keep] = answer.lam * reduced.scales.force
        return answer.u * reduced.scales.displacement, lam
""")


@pytest.fixture(scope="module")
def exact():
    result = signorini.solve("block", "pdas")
    assert result.converged
    return result


@pytest.fixture
def ignoring(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ignoring.py").write_text(IGNORES)
    return "ignoring.py:ignores_eight"


def _answer(result, u=None, lam=None):
    solution = result.solution
    return signorini.ContactSolution("edited", solution.u if u is None else u,
                                     solution.lam if lam is None else lam, "converged")


def test_an_ignored_constraint_is_named_with_its_point_and_the_advice_fits(ignoring):
    result = signorini.solve("block", ignoring)
    assert result.status == "inaccurate"
    assert "constraint 8 ignored" in result.message and "(0.5, 0)" in result.message
    assert "tighten the tolerance" not in result.message, result.message


def test_a_penetrating_node_with_no_force_is_apart_not_weak(ignoring, exact):
    wrong = signorini.solve("block", ignoring)
    labels = classify(wrong.problem, wrong.solution)
    assert labels[8] == INACTIVE and WEAK not in set(labels)
    found = compare(wrong.problem, exact.solution, wrong.solution)
    assert found.misclassified == 1 and found.weak == 0


@pytest.mark.parametrize("kind", ["tension", "complementarity", "stationarity", "penetration"])
def test_each_kind_of_failure_is_found_at_its_candidate(exact, kind):
    problem, lam, u = exact.problem, exact.solution.lam.copy(), exact.solution.u.copy()
    if kind == "tension":
        lam[3] = -0.5 * lam.max()
    elif kind == "complementarity":  # a force where the gap is open: lift node 5 off the flat
        u = u + 0.1 * np.abs(problem.N[5].toarray().ravel()) * np.abs(u).max()
    elif kind == "stationarity":
        lam[4] *= 1.5
    else:
        u = u - 0.1 * np.abs(problem.N[6].toarray().ravel()) * np.abs(u).max()
    edited = _answer(exact, u, lam)
    index = {"tension": 3, "complementarity": 5, "stationarity": 4, "penetration": 6}[kind]
    found = [v for v in violations(problem, edited, 1e-8) if v.kind == kind]
    assert found and found[0].index == index, found
    said = explain(problem, edited, 1e-8)
    assert f"candidate {index}" in said
    words = {"tension": "λ < 0", "complementarity": "force at a distance",
             "stationarity": "no equilibrium", "penetration": "penetration"}[kind]
    assert words in said, said


def test_an_exact_answer_has_no_violation(exact):
    assert violations(exact.problem, exact.solution, 1e-8) == []
    assert explain(exact.problem, exact.solution, 1e-8) is None


def test_crosscheck_json_and_v_give_a_table_per_candidate(ignoring, capsys):
    code = main(["crosscheck", "block", "--method", ignoring, "--method", "pdas", "--json", "c.json"])
    assert code == 1
    record = json.loads(open("c.json").read())
    row = record["candidates"][8]
    assert row["index"] == 8 and row["point"] == [0.5, 0.0]
    assert row["class"] == {ignoring: "penetrating", "pdas": "active"}
    assert row["gap"][ignoring] < 0 < row["lam"]["pdas"] and row["lam"][ignoring] == 0
    assert len(record["candidates"]) == record["contact_candidates"]
    capsys.readouterr()
    main(["-v", "crosscheck", "block", "--method", ignoring, "--method", "pdas"])
    out = capsys.readouterr().out
    assert "per candidate" in out and f"class {ignoring}" in out
    line = next(x for x in out.splitlines() if x.startswith("8 "))
    assert "penetrating" in line and "active" in line
