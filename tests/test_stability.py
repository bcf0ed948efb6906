"""The stability atlas: key facts on tiny problems, and its machinery.

Pinned facts: plain Uzawa converges at 0.95 × 2/λ_max(W) and diverges at
1.25 ×; the package never says ``converged`` when the certificate or the
exact answer disagrees; a weakly active node is not misclassified; the
force-controlled block is singular and its regularisation costs little;
ill-posed input is diagnosed; a run that hangs costs one row.
"""

import json
import textwrap

import numpy as np
import pytest

import signorini
from signorini.certification.diagnosis import diagnose, regularise
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.certification.kkt import certificate, classify
from signorini.problem.contact import ContactSolution
from signorini.scenes import build_problem
from signorini.scenes.block import force_controlled_exact, force_controlled_problem
from signorini.solvers.registry import solve
from signorini.studies.atlas import AXES, atlas_methods, run_atlas, select_axes
from signorini.studies.atlas.report import write_report
from signorini.studies.atlas.summary import wrapper_record
from signorini.studies.problems import ill_posed_problem
from signorini.studies.runner import BUILD_ONLY, Task, run_task, run_tasks
from signorini.studies.task import verdict

TINY_HERTZ = {"n_contact": 8, "grading": 0.5}
TINY_BLOCK = {"nx": 4, "ny": 4}


@pytest.fixture(scope="module")
def hertz():
    return signorini.at_load(build_problem("hertz-cylinder", params=TINY_HERTZ))


@pytest.fixture(scope="module")
def block():
    return signorini.at_load(build_problem("block", params=TINY_BLOCK))


# --- Uzawa's step bound -------------------------------------------------------------------------


@pytest.mark.parametrize("scene", ["hertz", "block"])
def test_uzawa_converges_inside_the_bound_and_diverges_beyond(scene, hertz, block):
    problem = {"hertz": hertz, "block": block}[scene]
    exact = solve(problem, "pdas", tol=1e-9)
    inside = solve(problem, "uzawa", tol=1e-8, step_fraction=0.95)
    assert inside.status == "converged"
    assert inside.extras["rho_over_bound"] == pytest.approx(0.95)
    assert compare(problem, exact, inside).lam_rel < 1e-6
    beyond = solve(problem, "uzawa", tol=1e-8, step_fraction=1.25, max_iter=5000)
    assert beyond.status == "diverged"
    assert beyond.extras["rho_over_bound"] == pytest.approx(1.25)
    assert "cycle" in beyond.message and "lower rho or step_fraction" in beyond.message


def test_the_block_diverges_just_beyond_the_bound(block):
    # every bottom node is active, so the active block of W is W itself: no slack beyond 1
    assert solve(block, "uzawa", tol=1e-8, step_fraction=1.05, max_iter=5000).status == "diverged"


# --- the package's status against the certificate and the exact answer ---------------------------


@pytest.mark.parametrize("method, tol", [("qp-osqp", None), ("qp-osqp", 1e-3), ("qp-clarabel", 1e-8),
                                         ("qp-scs", 1e-4), ("uzawa", 1e-4), ("cvxpy", 1e-8)])
def test_converged_only_when_the_certificate_and_the_exact_answer_agree(hertz, method, tol):
    row = run_task(Task("test", "tiny", 0, {"kind": "scene", "scene": "hertz-cylinder",
                                            "params": TINY_HERTZ}, method, tol=tol))
    assert row["wrapper_right"], row
    if row["status"] == "converged":
        assert row["cert_ok"] and row["exact_ok"]
        assert row["kkt_worst"] <= (tol or 1e-6)
    if row["claimed_status"] == "converged" and not row["cert_ok"]:
        assert row["status"] == "inaccurate" and "claimed success" in row["message"]


def test_osqp_at_its_defaults_claims_success_and_is_caught(hertz):
    solution = solve(hertz, "qp-osqp", polish=False)  # OSQP's own answer, not the polished one
    worst = certificate(hertz, solution).worst()[1]
    assert solution.claimed_status == "converged"
    assert worst > 1e-6 and solution.status == "inaccurate"


def test_verdict_flags_a_converged_status_with_a_wrong_answer():
    task = Task("test", "made up", 0, {}, "pdas")
    wrong = verdict({"status": "converged", "claimed_status": "converged", "cert_ok": True,
                     "exact_ok": False}, task)
    assert not wrong["wrapper_right"] and wrong["outcome"] == "wrong" and not wrong["claim_correct"]
    caught = verdict({"status": "inaccurate", "claimed_status": "converged", "cert_ok": False,
                      "exact_ok": False}, task)
    assert caught["wrapper_right"] and caught["outcome"] == "caught"
    conservative = verdict({"status": "inaccurate", "claimed_status": "converged",
                            "cert_ok": False, "exact_ok": True}, task)
    assert conservative["wrapper_right"] and conservative["outcome"] == "conservative"
    raised = verdict({"status": "raised", "claimed_status": "converged", "cert_ok": True,
                      "exact_ok": True}, task)
    assert not raised["wrapper_right"]


# --- degenerate contact --------------------------------------------------------------------------


def test_the_touching_block_has_weakly_active_nodes_and_keeps_its_default(block):
    assert block.model.params["touching"] == 0.0
    plain = signorini.at_load(build_problem("block", params={**TINY_BLOCK, "touching": 0.0}))
    assert abs(plain.K - block.K).max() == 0 and np.array_equal(plain.d, block.d)
    problem = signorini.at_load(build_problem("block", params={**TINY_BLOCK, "touching": 0.5}))
    exact = solve(problem, "pdas", tol=1e-9)
    labels = classify(problem, exact)
    assert np.sum(labels == "weak") >= 2 and np.sum(labels == "active") >= 2
    assert np.all(problem.d[labels == "weak"] > 0)  # they start apart and end touching


def test_a_weakly_active_node_is_not_misclassified():
    problem = signorini.at_load(build_problem("block", params={**TINY_BLOCK, "touching": 0.5}))
    exact = solve(problem, "pdas", tol=1e-9)
    weak = classify(problem, exact) == "weak"
    lam = exact.lam.copy()
    lam[weak] = 1e-9 * lam.max()  # a force of round-off size where the exact one is zero
    nearby = ContactSolution("perturbed", exact.u, lam, "converged")
    assert compare(problem, exact, nearby).misclassified == 0
    assert compare(problem, exact, nearby).weak == int(weak.sum())
    # without the weak band the same round-off force decides: those nodes count as active
    assert np.all(classify(problem, nearby, weak_tol=0.0)[weak] == "active")
    assert np.all(classify(problem, nearby)[weak] == "weak")
    inexact = solve(problem, "uzawa", tol=1e-8)
    assert inexact.status == "converged"
    assert compare(problem, exact, inexact).misclassified == 0


def test_a_small_touching_fraction_leaves_the_outer_corner_touching():
    problem = signorini.at_load(build_problem("block", params={"nx": 4, "ny": 4, "touching": 0.01}))
    labels = classify(problem, solve(problem, "pdas", tol=1e-9))
    assert labels[-1] == "weak" and np.sum(labels == "weak") == 1


# --- a body held only by contact -----------------------------------------------------------------


def test_force_controlled_block_is_singular_and_its_patch_solution_is_exact():
    problem = force_controlled_problem(params=TINY_BLOCK)
    exact = force_controlled_exact(problem)
    cert = certificate(problem, exact, duality_gap=False)
    assert cert.worst()[1] < 1e-12
    assert problem.total_contact_force(exact.lam) == pytest.approx(problem.model.load_offset, rel=1e-12)
    assert any("singular" in line for line in diagnose(problem))


def test_regularisation_makes_every_k_inverse_method_work_at_a_small_cost():
    problem = force_controlled_problem(params=TINY_BLOCK)
    exact = force_controlled_exact(problem)
    regularised = regularise(problem, 1e-8)
    assert diagnose(regularised) == []
    # condensed's dense LCP on the nearly singular W leaves λ 1.3e-9 off its QP's answer: the
    # certificate's forward error sees it at tol 1e-9, so it is held to 1e-8 here
    for method, tol in (("pdas", 1e-9), ("condensed", 1e-8)):
        solution = solve(regularised, method, tol=tol)
        assert solution.status == "converged"
        assert compare(problem, exact, solution).lam_rel < 1e-6
    coarse = solve(regularise(problem, 1e-2), "pdas", tol=1e-9)
    assert compare(problem, exact, coarse).lam_rel > 1e-4  # a big spring visibly takes load


@pytest.mark.parametrize("epsilon", [0.0, -1e-8, float("nan"), float("inf"), "1e-8", True])
def test_regularise_refuses_a_bad_epsilon(epsilon):
    with pytest.raises(InputError, match="epsilon"):
        regularise(force_controlled_problem(params=TINY_BLOCK), epsilon)


@pytest.mark.parametrize("method", ["pdas", "qp-clarabel"])
def test_a_singular_k_gets_a_status_not_an_exception(method):
    solution = solve(force_controlled_problem(params=TINY_BLOCK), method, tol=1e-8)
    assert solution.status in ("converged", "inaccurate", "failed")


# --- ill-posed input -----------------------------------------------------------------------------


def test_ill_posed_inputs_are_refused_or_diagnosed(block):
    with pytest.raises(InputError, match="no contact candidates"):
        ill_posed_problem("no-candidates", params=TINY_BLOCK)
    with pytest.raises(InputError, match="weight 0"):
        ill_posed_problem("zero-weight", params=TINY_BLOCK)
    penetrated = ill_posed_problem("penetrated", params=TINY_BLOCK)
    assert any(line.startswith("infeasible") for line in diagnose(penetrated))
    for method in ("pdas", "uzawa", "qp-clarabel"):
        assert solve(penetrated, method, tol=1e-8).status in ("infeasible", "failed")
    duplicate = ill_posed_problem("duplicate", params=TINY_BLOCK)
    assert any("not unique" in line for line in diagnose(duplicate))
    assert diagnose(block) == []
    with pytest.raises(InputError, match="unknown ill-posed case"):
        ill_posed_problem("upside-down")


# --- the machinery -------------------------------------------------------------------------------


@pytest.mark.slow
def test_a_hanging_method_costs_one_row(tmp_path):
    slow = tmp_path / "slow.py"
    slow.write_text(textwrap.dedent("""
        import time
        def solve(problem, *, tol=None, max_iter=None, **options):
            time.sleep(120)
    """))
    spec = {"kind": "scene", "scene": "block", "params": TINY_BLOCK}
    tasks = [Task("test", "hang", 0, spec, f"{slow}:solve"), Task("test", "after", 0, spec, "pdas")]
    rows = run_tasks(tasks, isolate=True, time_limit=10.0)
    assert rows[0]["status"] == "timeout" and rows[0]["wrapper_right"]
    assert rows[1]["status"] == "converged" and rows[1]["outcome"] == "right"


def test_each_axis_is_one_module_with_everything_about_it():
    assert [a.number for a in AXES] == list(range(1, len(AXES) + 1))
    # one module per axis, holding its tasks and its report together
    assert len({a.tasks.__module__ for a in AXES}) == len(AXES)
    assert all({f.__module__ for f in (a.findings, a.headline, a.table, a.figure)}
               == {a.tasks.__module__} for a in AXES)
    methods = atlas_methods(quick=True)
    for axis in AXES:
        assert axis.setup and axis.advice and axis.legend.startswith(("Cells", "Mesh A"))
        assert axis.tasks(True, methods), axis.name
        assert {t.axis for t in axis.tasks(True, methods)} == {axis.name}
    assert select_axes(["uzawa-step", "8", "1"]) == (AXES[0], AXES[7])


def test_a_quick_axis_writes_its_files(tmp_path, saved_figures):
    result = run_atlas(select_axes(["1"]), quick=True, isolate=False)
    assert {r["axis"] for r in result.rows} == {"uzawa-step"}
    paths = write_report(result, tmp_path, "signorini stability --axis 1 --quick")
    report = (tmp_path / "stability.md").read_text()
    assert report.startswith("# signorini stability atlas") and "--axis 1 --quick" in report
    assert "## 1. Uzawa's step" in report and "## 2." not in report
    lines = (tmp_path / "stability" / "runs.csv").read_text().strip().splitlines()
    assert len(lines) == 1 + len(result.rows) and lines[0].startswith("axis,case,value")
    data = json.loads((tmp_path / "stability" / "runs.json").read_text())
    assert data["wrapper"]["runs"] == len(result.rows)
    assert (tmp_path / "stability" / "axis1-uzawa-step.png").stat().st_size > 10_000
    # the figure: iterations against the step, one line per scene and method, the bound at 1
    (ax,) = saved_figures[0].axes
    assert ax.get_xlabel() == "step ρ / (2/λ_max(W))" and ax.get_xscale() == "log"
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert "ρ = 2/λ_max(W)" in lines and list(lines["ρ = 2/λ_max(W)"].get_xdata()) == [1.0, 1.0]
    for (case, method) in {(r["case"], r["method"]) for r in result.rows}:
        mine = sorted((r for r in result.rows if (r["case"], r["method"]) == (case, method)),
                      key=lambda r: r["value"])
        line = lines[f"{case}, {method}"]
        np.testing.assert_allclose(line.get_xdata(), [r["value"] for r in mine])
        np.testing.assert_allclose(line.get_ydata(), [max(r["iterations"], 1) for r in mine])
    assert paths["report"] == tmp_path / "stability.md"
    right, runs, faults = wrapper_record(result.rows)
    assert right == runs and not faults
    statuses = {(r["case"], r["value"]): r["status"] for r in result.rows}
    assert statuses[("block", 0.95)] == "converged" and statuses[("block", 1.25)] == "diverged"


def test_the_build_only_task_reports_the_diagnosis():
    row = run_task(Task("ill-posed", "penetrated", "penetrated",
                        {"kind": "ill-posed", "case": "penetrated", "params": TINY_BLOCK},
                        BUILD_ONLY, expect="refuse", measure=("diagnosis",)))
    assert row["status"] == "built" and row["outcome"] == "right"
    assert "infeasible" in row["diagnosis"]


def test_the_stability_command_runs_one_quick_axis(tmp_path, capsys):
    from signorini.cli import main

    code = main(["stability", "--quick", "--axis", "uzawa-step", "--in-process",
                 "--out", str(tmp_path)])
    out, err = capsys.readouterr()
    assert code == 0 and "right in" in out and "axis 1" in err
    assert (tmp_path / "stability.md").exists()


def test_the_committed_report_is_what_its_runs_give():
    # docs/stability.md is written from the rows alone: the committed runs.json gives it back
    from pathlib import Path

    from signorini.studies.atlas import AtlasResult, report_markdown

    docs = Path(__file__).resolve().parents[1] / "docs"
    data = json.loads((docs / "stability" / "runs.json").read_text(encoding="utf-8"))
    result = AtlasResult(data["rows"], tuple(a for a in AXES if a.name in data["axes"]),
                         data["elapsed_s"], data["axis_seconds"], data["quick"])
    text = report_markdown(result, data["command"], data["provenance"])
    assert text == (docs / "stability.md").read_text(encoding="utf-8")
