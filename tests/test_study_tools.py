"""The tools/ scripts that write committed artefacts run their cases through the studies' runner:
one small case of each, through the script's own task list, against the direct computation."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import signorini
from signorini.studies.runner import run_tasks

TOOLS = Path(__file__).resolve().parents[1] / "tools"


def tool(name: str):
    spec = importlib.util.spec_from_file_location(f"{name}_tool", TOOLS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_an_accuracy_case_is_the_public_solve_measured_against_hertz():
    accuracy = tool("accuracy")
    case = {"table": "cylinder", "scene": "hertz-cylinder", "loading": "traction",
            "mesher": "relaxed", "n_contact": 16, "grading": 0.15, "nu": 0.3, "a_over_R": 0.05,
            "volumetric": "element"}
    row = accuracy.run([case])[0]
    params = {k: case[k] for k in accuracy.PARAMS}
    direct = signorini.solve("hertz-cylinder", params=params, tol=1e-10)
    hertz = direct.hertz
    assert row["status"] == direct.status == "converged"
    assert row["dofs"] == direct.problem.n and row["nonzeros"] == direct.problem.K.nnz
    assert row["a_err"] == pytest.approx(hertz.a / hertz.a_ref - 1, abs=1e-9)
    assert row["p0_err"] == pytest.approx(hertz.p0 / hertz.p0_ref - 1, abs=1e-9)
    assert row["p0_nodal_err"] == pytest.approx(hertz.p0_nodal / hertz.p0_ref - 1, abs=1e-9)
    assert row["l2"] == pytest.approx(hertz.pressure_l2_rel, abs=1e-9)


def test_the_certificate_study_holds_each_method_to_the_refined_answer():
    study = tool("certificate_study")
    tasks = [t for t in study.tasks((0.3,)) if t.method in ("pdas", "uzawa")]
    rows = {r["method"]: study.row_of(r) for r in run_tasks(tasks, isolate=False)}
    assert rows["pdas"]["lam_error"] < 1e-10  # exact, to round-off
    uzawa = rows["uzawa"]
    assert rows["pdas"]["lam_error"] < uzawa["lam_error"] < 1e-6  # stopped at tol 1e-8
    assert 0.5 < uzawa["force_error"] / uzawa["lam_error"] < 2  # the certificate's estimate
    assert uzawa["force_error_floor"] < uzawa["force_error"] and uzawa["back_solves"] > 0


def test_a_crosscheck_case_is_the_public_crosscheck():
    pytest.importorskip("osqp")
    crosscheck = tool("crosscheck_cases")
    from signorini.studies.suite import DEFAULT_CASES

    block = next(c for c in DEFAULT_CASES if c.name == "block")
    task = next(t for t in crosscheck.tasks([block]) if t.axis == "raw")
    task = type(task)(**{**task.as_dict(), "options": {"methods": ["qp-osqp", "pdas"],
                                                       "options": {"qp-osqp": {"polish": False}}}})
    record = run_tasks([task], isolate=False)[0]["crosscheck"]
    direct = signorini.crosscheck(signorini.build_problem(block.scene, params=block.params),
                                  ["qp-osqp", "pdas"], tol=crosscheck.TOL,
                                  options={"qp-osqp": {"polish": False}}).to_dict()
    assert record["passed"] == direct["passed"] and record["dofs"] == direct["dofs"]
    assert [m["status"] for m in record["methods"]] == [m["status"] for m in direct["methods"]]
    assert record["pairs"][0]["lam_rel"] == pytest.approx(direct["pairs"][0]["lam_rel"], rel=1e-6)
    assert crosscheck.verdict(record, "qp-osqp")["ok"] == crosscheck.verdict(direct, "qp-osqp")["ok"]


def test_factor_memory_is_measured_in_a_process_of_its_own():
    pytest.importorskip("pypardiso", reason="the estimate is PARDISO's analysis (extra 'pardiso')")
    from signorini.numerics.factor import PardisoFactor

    study = tool("factor_memory")
    model = ("hertz-cylinder", {"n_contact": 16, "delta": 0.001})
    row = study.run([model])[0]
    problem = signorini.build_problem(*model[:1], params=model[1])
    assert row["dofs"] == problem.n
    assert row["estimate_bytes"] == PardisoFactor(problem.K).memory  # the analysis is deterministic
    assert row["resident_growth_bytes"] > 0 and np.isfinite(row["ratio"])


def test_an_effectivity_level_is_measured_against_the_finer_solve():
    study = tool("estimate")
    from signorini.studies.measures import energy_error

    task = next(t for t in study.tasks() if t.case == "hertz-cylinder" and t.value == 0)
    task = type(task)(**{**task.as_dict(), "reference": {
        "kind": "none", "finer": {**task.reference["finer"], "levels": [2]}}})
    row = run_tasks([task], isolate=False)[0]
    params = task.problem["params"]
    coarse, _ = study.solve("hertz-cylinder", params["n_contact"], params["grading"], 0)
    fine, _ = study.solve("hertz-cylinder", params["n_contact"], params["grading"], 2)
    direct = energy_error(coarse.problem, coarse.solution, fine.problem, fine.solution, 2)
    assert row["finer"]["2"]["dofs"] == fine.problem.n and row["dofs"] == coarse.problem.n
    assert row["finer"]["2"]["error"] == pytest.approx(direct["error"], rel=1e-8)
    assert row["estimate"]["eta"] == pytest.approx(coarse.estimate.total, rel=1e-8)


def test_a_whole_command_is_a_process_of_its_own_with_its_record():
    amg = tool("amg_bench")
    params = {"delta": 0.0025}
    run = amg.whole(params, method="pdas")
    assert run["returncode"] == 0 and run["record"]["status"] == "converged"
    assert run["record"]["dofs"] == signorini.build_problem("hertz-sphere-3d", params=params).n
    assert run["peak_gb"] > 0 and run["wall_s"] > 0
    assert run["command"].endswith("signorini solve hertz-sphere-3d --set delta=0.0025 --method pdas")


def test_a_whole_command_past_its_limit_is_stopped():
    amg = tool("amg_bench")
    run = amg.timed(["-c", "import time; time.sleep(60)"], timeout=1.0)
    assert run["returncode"] is None and run["said"] == "timed out" and run["record"] is None


def test_a_two_body_case_is_the_public_solve_of_its_scene():
    two_bodies = tool("two_bodies")
    case = next(c for c in two_bodies.cases() if c["table"] == "patch" and c["label"] == "1.7"
                and c["discretisation"] == "nts")
    row = two_bodies.run([case])[0]
    direct = signorini.solve("two-block-patch", "pdas", tol=case["tol"], params=case["params"])
    assert row["status"] == direct.status == "converged" and row["dofs"] == direct.problem.n
    assert row["reference"]["pressure_max_rel"] == pytest.approx(
        direct.comparison.pressure_max_rel, rel=1e-9)
    assert row["reference"]["pressure_max_rel"] > 1e-6  # node-to-segment fails the patch test
