"""``signorini crosscheck`` and ``signorini.crosscheck``: every pair of methods compared, liars caught."""

from __future__ import annotations

import json
from types import MappingProxyType

import numpy as np
import pytest

import signorini
from signorini.cli import main
from signorini.crosschecking import AGREE_FACTOR, DEFAULT_METHODS, agreement
from signorini.errors import InputError
from signorini.solvers.base import Method
from signorini.solvers import registry
from signorini.solvers.registry import REGISTRY, get_method

#: a method that says converged with a perturbed λ (pdas's answer, λ on the contact zone 1 % up)
LIAR = '''
import numpy as np
from signorini.solvers.registry import solve as registry_solve


def lying(problem, *, tol=None, max_iter=None, **options):
    """pdas's answer with λ 1 % too large on the contact zone, claimed converged."""
    solution = registry_solve(problem, "pdas", tol=tol)
    solution.lam = np.where(solution.lam > 0, 1.01 * solution.lam, solution.lam)
    solution.status, solution.claimed_status, solution.message = "converged", "", "trust me"
    return solution
'''


def require(*methods: str) -> None:
    for method in methods:
        for module in get_method(method).requires:
            pytest.importorskip(module, reason=f"{method} needs the module {module!r}")


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture()
def liar(tmp_path):
    path = tmp_path / "liar.py"
    path.write_text(LIAR)
    return f"{path}:lying"


def test_default_methods_agree_on_hertz_cylinder(capsys, tmp_path):
    require(*DEFAULT_METHODS)
    path = tmp_path / "cross.json"
    code, out, err = run(capsys, "crosscheck", "hertz-cylinder", "--json", str(path))
    assert code == 0, out + err
    assert "cross-check of hertz-cylinder" in out and "p0 err" in out
    for name in DEFAULT_METHODS:
        assert f"\n{name} " in out
    pairs = [line for line in out.splitlines() if " ~ " in line]
    assert len(pairs) == 10 and all(line.endswith("agree") for line in pairs)
    assert "passed: every method converged and every judged pair agrees (10 of 10" in out
    # each backend's own answer is judged and shown: no polish of ours, λ against pdas's
    record = json.loads(path.read_text())
    assert "λ vs pdas" in out and "polished λ" not in out and not record["polish"]
    for run_ in record["methods"]:
        assert run_["polished"] is None and "polished" not in run_["message"], run_["method"]
        assert run_["lam_ref"] <= AGREE_FACTOR * 1e-8 and run_["apart_ref"] == 0
        assert run_["active"] == record["methods"][-1]["active"] > 0
        assert run_["iterations"] > 0, run_["method"]  # the backend's own count (Clarabel's too)


def test_an_inaccurate_method_fails_the_check_unless_allowed(capsys):
    require("qp-ecos")
    argv = ["crosscheck", "block", "--method", "qp-ecos", "--method", "pdas", "--tol", "1e-9"]
    code, out, _ = run(capsys, *argv)
    ecos = next(line for line in out.splitlines() if line.startswith("qp-ecos"))
    assert "inaccurate" in ecos and code == 1
    assert out.rstrip().splitlines()[-1].startswith("FAILED: qp-ecos inaccurate")
    code, out, _ = run(capsys, *argv, "--allow", "qp-ecos")
    assert code == 0 and "qp-ecos (allowed)" in out and "allowed through: qp-ecos" in out
    check = signorini.crosscheck("block", ["qp-ecos", "pdas"], tol=1e-9)
    assert not check.passed and check.failures == ["qp-ecos inaccurate"]
    assert check.to_dict()["failures"] == check.failures


def test_a_method_that_does_not_converge_on_a_users_problem_is_named():
    require("qp-osqp")
    check = signorini.crosscheck(small_problem(), ["qp-osqp", "pdas"], tol=1e-10,
                                 options={"qp-osqp": {"max_iter": 1, "polishing": False}})
    assert not check.passed and check.failures == [f"qp-osqp {check.runs[0].status}"]
    assert check.runs[0].status != "converged"
    assert signorini.crosscheck(small_problem(), ["qp-osqp", "pdas"], tol=1e-10,
                                options={"qp-osqp": {"max_iter": 1, "polishing": False}},
                                allow=["qp-osqp"]).passed


def test_polish_is_an_extra_column_not_the_judged_answer(capsys):
    require("qp-clarabel")
    check = signorini.crosscheck("block", ["qp-clarabel", "pdas"], tol=1e-8, polish=True)
    clarabel, pdas = check.runs
    assert clarabel.polished is None and clarabel.polished_status == "converged"
    assert clarabel.polished_lam_ref is not None and clarabel.polished_lam_ref <= clarabel.lam_ref
    assert pdas.polished_status is None
    assert "polished" not in check.results["qp-clarabel"].message
    assert "polished λ vs pdas" in check.summary()
    # a caller's own polish wins: then the judged answer is the polished one
    own = signorini.crosscheck("block", ["qp-clarabel", "pdas"], tol=1e-8,
                               options={"qp-clarabel": {"polish": True}})
    assert own.runs[0].polished is not None


def test_a_method_that_lies_makes_it_exit_1(capsys, liar, tmp_path):
    md = tmp_path / "cross.md"
    code, out, _ = run(capsys, "crosscheck", "hertz-cylinder", "--method", "pdas",
                       "--method", "uzawa", "--method", liar, "--md", str(md))
    assert code == 1
    # it said converged (the certificate says otherwise), and disagrees with both others
    liar_row = next(line for line in out.splitlines() if line.startswith(liar))
    assert "converged → inaccurate" in liar_row
    assert f"pdas ~ {liar}" in out and f"uzawa ~ {liar}" in out
    verdicts = {line.split()[0] + line.split()[2]: line.split()[-1]
                for line in out.splitlines() if " ~ " in line and not line.startswith("FAILED")}
    assert verdicts == {"pdasuzawa": "agree", f"pdas{liar}": "DISAGREE",
                        f"uzawa{liar}": "DISAGREE"}
    assert f"FAILED: {liar} inaccurate; pdas ~ {liar} disagree; uzawa ~ {liar} disagree" in out
    assert "FAILED:" in md.read_text() and "| pdas ~ uzawa |" in md.read_text()


def test_the_api_returns_the_numbers_of_the_json(capsys, tmp_path):
    require("qp-osqp")
    path = tmp_path / "cross.json"
    methods = ["pdas", "uzawa", "qp-osqp"]
    code, _, _ = run(capsys, "crosscheck", "block", *[x for m in methods for x in ("--method", m)],
                     "--tol", "1e-9", "--json", str(path))
    assert code == 0
    written = json.loads(path.read_text())
    check = signorini.crosscheck("block", methods, tol=1e-9)
    record = json.loads(json.dumps(check.to_dict(), default=float))
    for run_ in written["methods"] + record["methods"]:
        run_.pop("time_s")  # the one number that differs between two runs
    assert written == record
    assert record["passed"] and len(record["pairs"]) == 3
    pair = check.pairs[0]
    assert (pair.first, pair.second) == ("pdas", "uzawa")
    assert pair.lam_rel == written["pairs"][0]["lam_rel"] and 0 < pair.lam_rel < 1e-8
    assert pair.limit == pytest.approx(AGREE_FACTOR * 1e-9)


def small_problem():
    # two springs, the first pressed onto its obstacle: λ = 0.5, the second free
    return signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.array([1.0, 1.0]),
                                            N=np.eye(2), d=np.array([0.25, 2.0]))


def test_agreement_judges_claims_and_leaves_weak_nodes_apart():
    problem = small_problem()
    exact = signorini.solve(problem, "pdas", tol=1e-12)
    near = signorini.solve(problem, "pdas", tol=1e-12)
    near.solution.lam = exact.solution.lam * (1 + 0.5 * AGREE_FACTOR * 1e-8)
    assert agreement(problem, exact.solution, near.solution, 1e-8, 1e-8).verdict == "agree"
    far = signorini.solve(problem, "pdas", tol=1e-12)
    far.solution.lam = exact.solution.lam * (1 + 2 * AGREE_FACTOR * 1e-8)
    pair = agreement(problem, exact.solution, far.solution, 1e-8, 1e-8)
    assert pair.verdict == "DISAGREE" and pair.apart == 0
    # a node on the other side of the zone's edge is apart
    flipped = signorini.solve(problem, "pdas", tol=1e-12)
    flipped.solution.lam = np.array([0.5, 0.4])  # λ̃ 0.8 against its gap 1 over 2: "active"
    assert agreement(problem, exact.solution, flipped.solution, 1e-2, 1e-2).apart == 1
    # ...unless both its force and its gap are within the looser tolerance: weakly active
    touching = signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.array([1.0, 0.0]),
                                                N=np.eye(2), d=np.array([0.25, 0.0]))
    a = signorini.solve(touching, "pdas", tol=1e-12)
    b = signorini.solve(touching, "pdas", tol=1e-12)
    b.solution.lam = np.array([0.5, 1e-7])
    pair = agreement(touching, a.solution, b.solution, 1e-6, 1e-6)
    assert (pair.apart, pair.weak) == (0, 1)
    # a method that did not say converged is shown, not judged
    far.solution.claimed_status, far.solution.status = "", "inaccurate"
    assert agreement(problem, exact.solution, far.solution, 1e-8, 1e-8).verdict == "not judged"


def test_a_missing_backend_is_a_row_not_an_error(monkeypatch):
    fake = Method(name="qp-nowhere", function=lambda problem, **_: None, summary="not here",
                  requires=("no_such_module_anywhere",))
    monkeypatch.setattr(registry, "REGISTRY", MappingProxyType({**REGISTRY, fake.name: fake}))
    check = signorini.crosscheck(small_problem(), ["pdas", "uzawa", "qp-nowhere"], tol=1e-10)
    assert [run.status for run in check.runs] == ["converged", "converged", "not installed"]
    assert len(check.pairs) == 1 and check.failures == ["qp-nowhere not installed"]


@pytest.mark.parametrize("argv, words", [
    (["--method", "no-such-method"], "unknown method"),
    (["--method", "pdas"], "at least two methods"),
    (["--method", "pdas", "--method", "pdas"], "named twice"),
    (["--method", "pdas", "--method", "uzawa", "--opt", "qp-osqp:polish=false"], "not among"),
    (["--method", "pdas", "--method", "uzawa", "--opt", "polish=false"], "METHOD:key=value"),
    (["--method", "pdas", "--method", "uzawa", "--allow", "qp-osqp"], "allow names 'qp-osqp'"),
    (["--tol", "2"], "--tol"),
    (["--json", "."], "is a directory"),
    (["--md", "/no/such/dir/x.md"], "does not exist"),
])
def test_bad_input_exits_2_before_any_solve(capsys, argv, words, monkeypatch):
    import signorini.crosschecking as module

    monkeypatch.setattr(module, "solve", lambda *a, **k: pytest.fail("solved before checking"))
    code, _, err = run(capsys, "crosscheck", "block", *argv)
    assert code == 2 and words in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_the_api_refuses_bad_input():
    with pytest.raises(InputError, match="list of names"):
        signorini.crosscheck("block", "pdas")
    with pytest.raises(InputError, match="params="):
        signorini.crosscheck(small_problem(), ["pdas", "uzawa"], params={"E": 2.0})


def _tool():
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("crosscheck_tool", root / "tools" / "crosscheck_cases.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool


def test_the_crosscheck_doc_is_its_runs_and_meets_the_issue():
    """docs/crosscheck.md's tables are what tools/crosscheck_cases.py renders from the committed
    JSON; in it every validation case has qp-osqp, qp-clarabel and cvxpy at tol 1e-8, polished
    (``solve``'s defaults), converged with λ within 1e-6 of pdas and its active set; their raw
    answers (what the cross-check judges) do the same on Hertz's cylinder — and the defaults
    that run was made with are the code's."""
    tool = _tool()
    from readme import current  # tools/readme.py, put on the path by the tool
    data = json.loads(tool.OUT.read_text())
    text = tool.DOC.read_text(encoding="utf-8")
    for name, body in tool.blocks(data).items():
        assert current(text, name) == body, f"docs/crosscheck.md block {name!r}: run tools/crosscheck_cases.py --doc"
    from signorini.solvers import cvxpy_, qp
    from signorini.studies.suite import DEFAULT_CASES

    polished = data["variants"]["polished"]
    assert sorted(polished) == sorted(case.name for case in DEFAULT_CASES)
    for record in polished.values():
        assert record["tol"] == 1e-8 and record["passed"] and not record["polish"]
        for method in ("qp-osqp", "qp-clarabel", "cvxpy", "uzawa"):
            verdict = tool.verdict(record, method)
            assert verdict["ok"], (record["case"], method, verdict)
    for record in data["variants"]["raw"].values():
        assert record["passed"] == (not record["failures"])
        assert all(run_["polished"] is None for run_ in record["methods"])
    cylinder = data["variants"]["raw"]["hertz-cylinder"]
    assert cylinder["passed"] and all(tool.verdict(cylinder, m)["ok"] for m in tool.QP_METHODS)
    assert qp.BACKEND_BY_NAME["osqp"].polish and qp.BACKEND_BY_NAME["clarabel"].polish
    assert cvxpy_.DEFAULT_POLISH
    assert qp.BACKEND_BY_NAME["clarabel"].tolerance(1e-8)["tol_gap_abs"] == 1e-14
    assert qp.BACKEND_BY_NAME["osqp"].tolerance(1e-8)["polishing"] is True


def test_the_validation_suite_cross_checks_uzawa_with_osqp_and_clarabel():
    """Every case: uzawa against qp-osqp and qp-clarabel (default form) at the suite's tight
    tolerance; a check that fails when they disagree, or when either did not converge."""
    require("qp-osqp", "qp-clarabel")
    from signorini.studies import suite, suite_checks

    cases = suite.select_cases(["block"])
    result = suite.run_suite(cases, ["uzawa", "qp-osqp", "qp-clarabel"], isolate=False)
    crossed = [c for c in result.checks if "cross-checked" in c.name]
    assert [c.name.split(" (")[0] for c in crossed] == ["uzawa cross-checked with qp-osqp",
                                                       "uzawa cross-checked with qp-clarabel"]
    assert all(c.passed for c in crossed) and result.passed
    case = result.results[0]
    lying = case.solutions[suite_checks.label("qp-clarabel", suite_checks.TIGHT_TOL)]
    lying.lam = 1.01 * lying.lam  # still says converged: the cross-check must catch it
    checks = suite_checks.cross_checks(case)
    assert [c.passed for c in checks] == [True, False]
    assert "λ 9.9e-03" in checks[1].detail  # 0.01 over the larger ‖λ‖∞
    case.solutions[suite_checks.label("qp-osqp", suite_checks.TIGHT_TOL)].status = "inaccurate"
    assert not suite_checks.cross_checks(case)[0].passed
