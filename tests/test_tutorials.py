"""The tutorials in docs/tutorials/ and their worked solutions: they run, are stored clean, the
exercises can be handed out alone, and what they teach works.

The notebooks are executed once, by the documentation site's build (``docs_site`` in conftest.py:
mkdocs-jupyter runs each notebook in a fresh kernel from its own folder, with the non-interactive
inline matplotlib backend, and a cell that raises fails the build). The tests here read the built
pages: each shows every figure its notebook draws. Each tutorial ends with its exercises; their
worked solutions are a notebook of their own in docs/tutorials/solutions/, which runs the tutorial
first and then solves the exercises.
"""

import os
import re
import sys
from pathlib import Path

import nbformat
import numpy as np
import pytest

from signorini import cli
from signorini.solvers.registry import get_method, solve
from signorini.studies import suite
from synthetic import random_problem

ROOT = Path(__file__).resolve().parents[1]
TUTORIALS = ROOT / "docs" / "tutorials"
SOLUTIONS = TUTORIALS / "solutions"
NOTEBOOKS = ("01-two-contact-points", "02-lagrangian-kkt-gap", "03-multipliers-to-pressure",
             "04-write-your-own-solver", "05-multipliers-are-prices")
USER_SOLVER = TUTORIALS / "one_shot_solver.py"
SMALL_CASES = tuple(case for case in suite.DEFAULT_CASES
                    if case.name in ("block", "hertz-cylinder-coarse"))
#: a figure in a notebook: one call that makes one (a figure drawn in a loop would need its count)
FIGURE_CALL = re.compile(r"\bplt\.(?:subplots|figure)\(")
#: a figure on a built page: the PNG that the inline backend rendered, embedded in the page
PAGE_FIGURE = re.compile(r'<img[^>]*src="data:image/png;base64,')


def _path(name: str) -> Path:
    return TUTORIALS / f"{name}.ipynb"


def _solutions(name: str) -> Path:
    return SOLUTIONS / f"{name}-solutions.ipynb"


#: every notebook of the site: the five tutorials, then their five solutions notebooks
EVERY_NOTEBOOK = [_path(name) for name in NOTEBOOKS] + [_solutions(name) for name in NOTEBOOKS]


def _read(path: Path) -> nbformat.NotebookNode:
    return nbformat.read(path, as_version=4)


def _code(notebook) -> list[str]:
    return [cell.source for cell in notebook.cells if cell.cell_type == "code"]


def _headings(notebook) -> list[str]:
    return [line for cell in notebook.cells if cell.cell_type == "markdown"
            for line in cell.source.splitlines() if line.startswith("## ")]


def test_the_tutorials_are_the_five_notebooks_and_their_solutions():
    assert sorted(p.stem for p in TUTORIALS.glob("*.ipynb")) == sorted(NOTEBOOKS)
    assert sorted(SOLUTIONS.glob("*.ipynb")) == sorted(_solutions(name) for name in NOTEBOOKS)


@pytest.mark.parametrize("path", EVERY_NOTEBOOK, ids=lambda path: path.stem)
def test_notebook_is_valid_and_saved_without_outputs(path):
    notebook = _read(path)
    nbformat.validate(notebook)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert code, "a notebook without code"
    assert all(cell.outputs == [] and cell.execution_count is None for cell in code), \
        "clear the outputs before saving (Kernel → Restart & Clear Output)"
    assert notebook.cells[0].cell_type == "markdown" and notebook.cells[0].source.startswith("# ")


@pytest.mark.slow
@pytest.mark.parametrize("path", EVERY_NOTEBOOK, ids=lambda path: path.stem)
def test_the_site_shows_every_figure_the_notebook_draws(path, docs_site):
    """The notebook ran headless in the site's build and its page carries the figures it draws:
    no fewer (a figure lost), and no more (the solutions show none of the tutorial's figures)."""
    built, site = docs_site
    assert built.returncode == 0, built.stderr[-4000:]
    page = site / path.parent.relative_to(ROOT / "docs") / path.stem / "index.html"
    shown = len(PAGE_FIGURE.findall(page.read_text(encoding="utf-8")))
    drawn = sum(len(FIGURE_CALL.findall(source)) for source in _code(_read(path)))
    assert shown == drawn, f"{path.name} draws {drawn} figures, its page shows {shown}"
    if path.parent == TUTORIALS:
        assert drawn > 0, f"{path.name} draws no figure"


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_the_exercises_can_be_handed_out_without_their_solutions(name):
    tutorial, solutions = _read(_path(name)), _read(_solutions(name))
    assert _headings(tutorial)[-1] == "## Exercises", "a tutorial ends with its exercises"
    assert not any("Worked solutions" in cell.source for cell in tutorial.cells)
    after = [cell.source for cell in tutorial.cells][
        next(i for i, cell in enumerate(tutorial.cells) if "## Exercises" in cell.source) + 1:]
    assert len(after) == 2 and after[0].startswith("The claims") and "assert" in after[1], \
        "after the exercises only the tutorial's own claims, checked"
    assert f"`solutions/{name}-solutions.ipynb`" in "".join(cell.source for cell in tutorial.cells)
    # the solutions run their tutorial first, from its folder, and solve nothing the tutorial already has
    setup = _code(solutions)[0]
    assert "%cd .." in setup and f"%run {name}.ipynb" in setup.splitlines()
    assert "## Worked solutions" in _headings(solutions)
    assert not set(_code(solutions)) & set(_code(tutorial))


@pytest.mark.parametrize("path", EVERY_NOTEBOOK, ids=lambda path: path.stem)
def test_notebook_uses_only_the_public_api(path):
    import signorini

    source = "\n".join(_code(_read(path)))
    imports = re.findall(r"^\s*(?:from|import)\s+(signorini\S*)", source, flags=re.M)
    assert imports == (["signorini"] if path.parent == TUTORIALS else [])
    assert set(re.findall(r"\bsignorini\.(\w+)", source)) <= set(signorini.__all__)


def test_readme_and_the_tutorials_page_link_every_tutorial_and_its_solutions():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = re.search(r"^## Tutorials\n(.*?)(?=^## |\Z)", readme, flags=re.S | re.M)
    assert section, "README.md has no '## Tutorials' section"
    assert "(docs/tutorials/solutions/)" in section.group(1)
    page = (ROOT / "docs" / "tutorials.md").read_text(encoding="utf-8")
    for name in NOTEBOOKS:
        assert f"(docs/tutorials/{name}.ipynb)" in section.group(1), name
        assert f"(tutorials/{name}.ipynb)" in page and f"(tutorials/solutions/{name}-solutions.ipynb)" in page


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
