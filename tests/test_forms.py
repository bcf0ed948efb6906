"""Formulations of the QP methods (``form=primal|shifted|dual``) and ``polish``.

Every form is the same contact problem: on the block and a small Hertz cylinder each
gives pdas's answer (λ and the active set); the shifted and dual forms cost what
their docstring says in factorisations and back-solves; bad options fail before any
work is done. The numbers of ``docs/formulations.md`` come from ``tools/formulations.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

import signorini
from signorini.errors import InputError
from signorini.certification.comparison import compare
from signorini.certification.kkt import force_scale, gap_scale
from signorini.numerics.factor import Work, counting
from signorini.problem.contact import ContactSolution
from signorini.solvers import forms, qp
from signorini.solvers.registry import get_method, solve

SCENES = {"block": {}, "hertz-cylinder": {"n_contact": 16, "grading": 0.4}}
#: clarabel and osqp, and SCS (a third, conic first-order backend); cvxpy with Clarabel
METHODS = ("qp-clarabel", "qp-osqp", "qp-scs", "cvxpy")


def require(method: str) -> None:
    for module in get_method(method).requires:
        pytest.importorskip(module, reason=f"{method} needs the module {module!r}")


@pytest.fixture(scope="module", params=sorted(SCENES))
def scene(request):
    problem = signorini.at_load(signorini.build_problem(request.param, params=SCENES[request.param]))
    return problem, solve(problem, "pdas", tol=1e-10)


@pytest.mark.parametrize("form", forms.FORMS)
@pytest.mark.parametrize("method", METHODS)
def test_every_form_gives_the_exact_answer(scene, method, form):
    require(method)
    problem, exact = scene
    raw = solve(problem, method, tol=1e-11, form=form)
    assert raw.extras["form"] == form
    found = compare(problem, raw, exact)
    assert found.lam_rel <= 1e-6 and found.u_rel <= 1e-6, (found, raw.message)
    assert found.misclassified == 0
    polished = solve(problem, method, tol=1e-11, form=form, polish=True)
    assert polished.status == "converged", polished.message
    assert compare(problem, polished, exact).lam_rel <= 1e-9
    assert polished.extras["polish"]["kept"] or raw.status == "converged"


#: the default forms docs/formulations.md chose by measurement (the rest stay primal)
DUAL_BY_DEFAULT = {"osqp", "highs", "daqp", "quadprog", "ecos"}


def test_the_default_form_is_the_backends_own():
    assert {b.name for b in qp.BACKENDS if b.form == "dual"} == DUAL_BY_DEFAULT
    assert all(b.form == "primal" for b in qp.BACKENDS if b.name not in DUAL_BY_DEFAULT)
    require("qp-osqp")
    problem = signorini.at_load(signorini.build_problem("block"))
    sol = solve(problem, "qp-osqp", tol=1e-9)
    assert sol.extras["form"] == "dual" and "(dual form)" in sol.message


def test_a_default_dual_falls_back_to_primal_where_it_cannot_be_built():
    """K singular (a body held by contact alone), or more candidates than max_dense_dofs: the
    default dual becomes the primal form and says why; asked for by name, it fails instead."""
    require("qp-osqp")
    from signorini.scenes.block import force_controlled_problem

    floating = force_controlled_problem(0.01)
    sol = solve(floating, "qp-osqp", tol=1e-9)
    assert sol.status == "converged", sol.message
    assert sol.extras["form"] == "primal" and "needs K⁻¹" in sol.extras["form_note"]
    asked = solve(floating, "qp-osqp", tol=1e-9, form="dual")
    assert asked.status == "failed" and "form=primal" in asked.message
    problem = signorini.at_load(signorini.build_problem("block"))
    sol = solve(problem, "qp-osqp", tol=1e-9, max_dense_dofs=problem.m - 1)
    assert sol.extras["form"] == "primal" and "max_dense_dofs" in sol.message
    with pytest.raises(InputError, match="form='dual' builds the dense"):
        solve(problem, "qp-osqp", tol=1e-9, form="dual", max_dense_dofs=problem.m - 1)


def test_superlu_on_a_singular_k_is_caught(monkeypatch):
    """SuperLU factorises a singular K without a word: K u₀ = f is checked."""
    from signorini.scenes.block import force_controlled_problem

    monkeypatch.setenv("SIGNORINI_FACTOR", "superlu")
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        forms.formulate(force_controlled_problem(0.01), "shifted")


def counted(function, *args, **kwargs):
    with counting() as work:
        out = function(*args, **kwargs)
    return out, {"factorisations": work.factorisations, "back_solves": work.back_solves}


@pytest.mark.parametrize("method", ("qp-clarabel", "cvxpy"))
def test_work_of_each_form(method):
    """primal: no linear algebra of K; shifted: one factorisation, one back-solve (u₀);
    dual: one factorisation and m + 2 back-solves (W, N K⁻¹ f, u). The certificate then
    reuses that factorisation: judging adds back-solves, no factorisation. (Unpolished:
    polish, the default of qp-clarabel and cvxpy, solves one more KKT system.)"""
    require(method)
    problem = signorini.at_load(signorini.build_problem("hertz-cylinder", params=SCENES["hertz-cylinder"]))
    m = problem.m
    expected = {"primal": (0, 0), "shifted": (1, 1), "dual": (1, m + 2)}
    for form, (factorisations, back_solves) in expected.items():
        fresh = problem.with_data()  # no cached factorisation of K
        sol, work = counted(get_method(method).function, fresh, tol=1e-9, form=form,
                            polish=False)
        assert (work["factorisations"], work["back_solves"]) == (factorisations, back_solves)
        assert sol.extras["form_work"] == work
        assert (sol.factor is not None) == (form != "primal")
        if form != "primal":
            _, judged = counted(solve, problem.with_data(), method, tol=1e-9, form=form,
                                polish=False)
            assert judged["factorisations"] == 1, form


@pytest.mark.parametrize("method", ("qp-osqp", "qp-clarabel", "cvxpy"))
@pytest.mark.parametrize("options, match", [
    ({"form": "primel"}, "form='primel' is not one of primal, shifted, dual"),
    ({"polish": "yes"}, "polish='yes' must be true or false"),
    ({"form": "dual", "max_dense_dofs": 5}, "form='dual' builds the dense m × m"),
    ({"form": "dual", "max_dense_dofs": 0}, "max_dense_dofs=0 must be an integer ≥ 1"),
])
def test_bad_options_fail_before_any_work(method, options, match):
    problem = signorini.at_load(signorini.build_problem("block"))
    if method == "cvxpy" and "max_dense_dofs" not in options:
        require(method)
    with counting() as work, pytest.raises(InputError, match=match):
        get_method(method).function(problem, tol=1e-9, **options)
    assert work == Work()


def test_api_and_every_qp_method_take_the_options():
    for backend in qp.BACKENDS:
        assert {"form", "polish"} <= set(get_method(backend.method_name).options)
    assert {"form", "polish"} <= set(get_method("cvxpy").options)
    require("qp-clarabel")
    problem = signorini.at_load(signorini.build_problem("block"))
    result = signorini.solve(problem, "qp-clarabel", tol=1e-9, form="shifted")
    assert result.status == "converged" and result.solution.extras["form"] == "shifted"
    assert "(shifted form)" in result.solution.message


def test_dense_backends_solve_the_dual_beyond_their_dof_limit():
    """The dual's unknowns are the m candidates: a dense backend takes n > max_dense_dofs."""
    require("qp-daqp")
    problem = signorini.at_load(signorini.build_problem("hertz-cylinder", params=SCENES["hertz-cylinder"]))
    exact = solve(problem, "pdas", tol=1e-10)
    with pytest.raises(InputError, match="max_dense_dofs"):
        solve(problem, "qp-daqp", tol=1e-9, form="primal", max_dense_dofs=500)
    sol = solve(problem, "qp-daqp", tol=1e-9, max_dense_dofs=500)  # its default: the dual
    assert sol.status == "converged" and sol.extras["form"] == "dual", sol.message
    assert compare(problem, sol, exact).lam_rel <= 1e-9


def test_polish_keeps_the_better_answer_and_records_both():
    require("qp-osqp")
    problem = signorini.at_load(signorini.build_problem("hertz-cylinder", params=SCENES["hertz-cylinder"]))
    exact = solve(problem, "pdas", tol=1e-10)
    # OSQP at its loose defaults: a rough answer that the polish repairs
    sol = solve(problem, "qp-osqp", polish=True)
    record = sol.extras["polish"]
    assert record["kept"] and sol.status == "converged", sol.message
    assert max(record["polished"].values()) < max(record["raw"].values())
    assert "the polished answer" in sol.message
    assert compare(problem, sol, exact).lam_rel <= 1e-9


def test_polish_on_a_wrong_active_set_is_not_kept():
    """An answer one node off the exact one: polishing on its active set (that node closed)
    pulls the node with a tensile force, and the raw answer is kept and said to be."""
    problem = signorini.at_load(signorini.build_problem("hertz-cylinder", params=SCENES["hertz-cylinder"]))
    exact = solve(problem, "pdas", tol=1e-10)
    gap = problem.gap(exact.u)
    node = int(np.argmin(np.where(exact.lam > 0, np.inf, gap)))  # the nearest open node
    lam = exact.lam.copy()
    lam[node] = 2 * gap[node] / gap_scale(problem, exact.u) * force_scale(problem, exact.lam)
    raw = ContactSolution("test", exact.u.copy(), lam, "converged", message="made up")
    form = forms.formulate(problem, "shifted")
    out = forms.polish(problem, form, raw, 1e-9)
    record = out.extras["polish"]
    assert record["active"] == int((exact.lam > 0).sum()) + 1
    assert not record["kept"] and "did not improve" in out.message
    assert out.lam is lam and record["polished"]["dual_sign"] > record["raw"]["dual_sign"]


def test_a_polished_answer_that_is_not_certified_says_so():
    """Polish keeps a better point whose certificate still misses the tolerance: the status
    stays the method's and the message does not end as if the answer were certified."""
    problem = signorini.build_problem("block")
    exact = solve(problem, "pdas", tol=1e-10)
    raw = ContactSolution("test", 1.001 * exact.u, 1.001 * exact.lam, "failed", message="made up")
    out = forms.polish(problem, forms.formulate(problem, "primal"), raw, 1e-30)
    assert out.extras["polish"]["kept"] and out.status == "failed"
    assert out.message.endswith("the polished answer, still failed (above 1e-30)"), out.message


def test_the_formulations_doc_is_its_runs():
    """docs/formulations.md's tables are what tools/formulations.py renders from the committed
    JSON (``python tools/formulations.py --doc``), and its defaults are the code's."""
    import importlib.util
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("formulations_tool", root / "tools" / "formulations.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    text = tool.DOC.read_text(encoding="utf-8")
    blocks = tool.tables(tool.load())
    assert set(blocks) >= {"summary", *tool.CASES}
    for name, body in blocks.items():
        found = tool.pattern(name).search(text)
        assert found and found.group(2) == body, (
            f"docs/formulations.md block '{name}' differs: run python tools/formulations.py --doc")
