"""The tutorials in docs/tutorials/: they run headless, are stored clean, and what they teach works.

Each notebook is executed in a fresh Jupyter kernel (nbclient) with the
non-interactive inline matplotlib backend, from its own directory, as a
student would run it. A cell that raises fails the test; so does an error
shown by a display hook, a notebook without figures, or one saved with outputs.
"""

import os
import re
import sys
from pathlib import Path

import nbclient
import nbformat
import numpy as np
import pytest

from signorini import cli
from signorini.solvers.registry import get_method, solve
from signorini.studies import suite
from synthetic import random_problem

ROOT = Path(__file__).resolve().parents[1]
TUTORIALS = ROOT / "docs" / "tutorials"
NOTEBOOKS = {
    "01-two-contact-points": 5,  # the figures each notebook must produce
    "02-lagrangian-kkt-gap": 3,
    "03-multipliers-to-pressure": 2,
    "04-write-your-own-solver": 1,
    "05-multipliers-are-prices": 5,
}
USER_SOLVER = TUTORIALS / "one_shot_solver.py"
#: matplotlib-inline renders every figure to PNG at the end of a cell and never opens a window
BACKEND = "module://matplotlib_inline.backend_inline"
CELL_TIMEOUT_S = 300
SMALL_CASES = tuple(case for case in suite.DEFAULT_CASES
                    if case.name in ("block", "hertz-cylinder-coarse"))


def _path(name: str) -> Path:
    return TUTORIALS / f"{name}.ipynb"


def test_the_tutorials_are_the_five_notebooks():
    assert sorted(p.stem for p in TUTORIALS.glob("*.ipynb")) == sorted(NOTEBOOKS)


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_is_valid_and_saved_without_outputs(name):
    notebook = nbformat.read(_path(name), as_version=4)
    nbformat.validate(notebook)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert code, "a tutorial without code"
    assert all(cell.outputs == [] and cell.execution_count is None for cell in code), \
        "clear the outputs before saving (Kernel → Restart & Clear Output)"
    assert notebook.cells[0].cell_type == "markdown" and notebook.cells[0].source.startswith("# ")


@pytest.mark.slow
@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_runs_headless(name, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", BACKEND)
    notebook = nbformat.read(_path(name), as_version=4)
    client = nbclient.NotebookClient(notebook, timeout=CELL_TIMEOUT_S, kernel_name="python3",
                                     resources={"metadata": {"path": str(TUTORIALS)}})
    client.execute()  # raises CellExecutionError, naming the cell, when a cell fails
    outputs = [out for cell in notebook.cells if cell.cell_type == "code" for out in cell.outputs]
    errors = [f"{out.ename}: {out.evalue}" for out in outputs if out.output_type == "error"]
    assert not errors, errors
    figures = sum("image/png" in out.get("data", {}) for out in outputs)
    assert figures >= NOTEBOOKS[name], f"{name} drew {figures} figures"


#: the notebooks rewritten on the public API alone (``import signorini``), with worked exercises
PUBLIC_API_ONLY = tuple(NOTEBOOKS)


@pytest.mark.parametrize("name", PUBLIC_API_ONLY)
def test_notebook_uses_only_the_public_api_and_ends_with_worked_exercises(name):
    import signorini

    notebook = nbformat.read(_path(name), as_version=4)
    source = "\n".join(cell.source for cell in notebook.cells if cell.cell_type == "code")
    assert re.findall(r"^\s*(?:from|import)\s+(signorini\S*)", source, flags=re.M) == ["signorini"]
    assert set(re.findall(r"\bsignorini\.(\w+)", source)) <= set(signorini.__all__)
    headings = [line for cell in notebook.cells if cell.cell_type == "markdown"
                for line in cell.source.splitlines() if line.startswith("## ")]
    assert headings.index("## Exercises") < headings.index("## Worked solutions")


def test_readme_links_every_tutorial():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = re.search(r"^## Tutorials\n(.*?)(?=^## |\Z)", readme, flags=re.S | re.M)
    assert section, "README.md has no '## Tutorials' section"
    for name in NOTEBOOKS:
        assert f"(docs/tutorials/{name}.ipynb)" in section.group(1), name


# --- the user-method protocol that tutorial 04 teaches --------------------------------------------


def test_a_solver_file_runs_through_the_registry():
    problem = random_problem(n=8, m=3, seed=2)
    method = get_method(f"{USER_SOLVER}:solve")
    assert method.family == "user" and "penetrat" in method.summary
    solution = solve(problem, f"{USER_SOLVER}:solve", tol=1e-9)
    assert solution.method == f"{USER_SOLVER}:solve"
    assert np.all(np.isfinite(solution.lam))


def test_run_suite_runs_a_solver_file_and_reports_where_it_is_wrong():
    spec = f"{USER_SOLVER}:solve"
    result = suite.run_suite(SMALL_CASES, method_names=[spec])
    rows = {row["case"]: row for row in result.runs}
    assert set(rows) == {"block", "hertz-cylinder-coarse"}
    assert all(row["method"] == spec for row in rows.values())
    block, hertz = rows["block"], rows["hertz-cylinder-coarse"]
    assert block["status"] == "converged" and block["vs_reference"]["lam_rel"] < 1e-10
    assert hertz["status"] == "inaccurate" and hertz["claimed_status"] == "converged"
    assert hertz["kkt"]["dual_sign"] > 0.5  # pulling forces
    assert hertz["vs_reference"]["misclassified"] > 0
    block_checks = [c for c in result.checks if c.case == "block" and spec in c.name]
    assert len(block_checks) == 3 and all(c.passed for c in block_checks)
    # a method asked for by name must converge: on the coarse Hertz case it does not
    named = [c for c in result.checks if c.name == f"{spec} (asked for by name) converged"]
    assert [c.passed for c in named] == [True, False]
    assert not result.passed


@pytest.mark.slow
def test_cli_validate_accepts_a_solver_file(tmp_path, monkeypatch, capsys):
    """``signorini validate --method path/to/file.py:solve``, on the two small default cases."""
    out = tmp_path / "report"
    code = cli.main(["validate", "--method", f"{USER_SOLVER}:solve", "--case", "block",
                     "--case", "hertz-cylinder-coarse", "--out", str(out)])
    report = (out / "report.md").read_text(encoding="utf-8")
    assert code == 1 and "Result: **FAIL**" in report  # the flawed solver fails the suite
    assert f"{USER_SOLVER}:solve@1e-09 | inaccurate (converged)" in report
    assert f"--method {USER_SOLVER}:solve" in report
    assert "checks passed" in capsys.readouterr().out


def test_module_form_is_found_from_the_tutorials_directory(monkeypatch):
    monkeypatch.chdir(TUTORIALS)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", str(TUTORIALS))])
    monkeypatch.delitem(sys.modules, "one_shot_solver", raising=False)
    assert get_method("one_shot_solver:solve").function.__module__ == "one_shot_solver"
    assert os.path.samefile(get_method("one_shot_solver:solve").function.__code__.co_filename,
                            USER_SOLVER)
