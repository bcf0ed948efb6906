"""Every key a JSON record can hold is documented in docs/json.md (and carries its schema)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import signorini
from signorini.api import SCHEMA_VERSION
from signorini.cli import main
from signorini.crosschecking import crosscheck
from signorini.files import to_json

DOC = Path(__file__).resolve().parents[1] / "docs" / "json.md"


def documented() -> set[str]:
    """The key paths in the first column of docs/json.md's tables (a cell may list several)."""
    paths = set()
    for line in DOC.read_text().splitlines():
        if line.startswith("| `"):
            paths |= set(re.findall(r"`([^`]+)`", line.split(" | ")[0]))
    return paths


def key_paths(value, prefix: str = "") -> set[str]:
    """Every key path of a JSON value: ``a.b`` for nested keys, ``a[].b`` for rows of a list."""
    found = set()
    if isinstance(value, dict):
        for key, inner in value.items():
            path = f"{prefix}.{key}" if prefix else key
            found |= {path} | key_paths(inner, path)
    elif isinstance(value, list):
        for row in value:
            if isinstance(row, dict):
                found |= key_paths(row, prefix + "[]")
    return found


def undocumented(paths: set[str]) -> set[str]:
    """Paths docs/json.md does not list, where ``*`` in a documented path stands for one key,
    and every path with a key that holds a space (a key is one word: ``load_control``)."""
    patterns = [re.compile(re.escape(p).replace(r"\*", r"[^.\[\]]+") + r"\Z") for p in documented()]
    return {p for p in paths if " " in p or not any(pattern.match(p) for pattern in patterns)}


def record(result) -> dict:
    return json.loads(to_json(result.to_dict()))


def test_the_docs_list_keys():
    assert {"schema_version", "units", "contact.pressure", "pairs[].verdict"} <= documented()
    assert undocumented({"no_such_key"}) == {"no_such_key"}  # the check can fail
    assert undocumented({"work.load control"}) == {"work.load control"}  # a key with a space
    assert not [path for path in documented() if " " in path]  # nor does the page list one


SOLVES = [("block", {"nx": 6, "ny": 6}, "auto"), ("hertz-cylinder", {"n_contact": 10}, "auto"),
          ("hertz-sphere", {"n_contact": 10}, "uzawa"),
          pytest.param("punch", {}, "qp-osqp", marks=pytest.mark.slow),
          pytest.param("reverse-hertz", {}, "qp-clarabel", marks=pytest.mark.slow),
          pytest.param("hertz-cylinder", {"n_contact": 10}, "cvxpy", marks=pytest.mark.slow),
          ("block", {"nx": 6, "ny": 6}, "nested"), ("block", {"nx": 6, "ny": 6}, "pdas-amg"),
          ("block", {"nx": 6, "ny": 6}, "uzawa-nesterov"), ("block", {"nx": 6, "ny": 6}, "condensed")]


@pytest.mark.parametrize("scene, params, method", SOLVES, ids=lambda x: x if isinstance(x, str) else "")
def test_every_key_of_a_solve_is_documented(scene, params, method):
    out = record(signorini.solve(scene, method, params=params))
    assert out["schema_version"] == SCHEMA_VERSION
    assert out["units"]["system"].startswith("the scene's")
    assert undocumented(key_paths(out)) == set()


def test_every_key_of_a_problem_from_its_qp_and_a_saved_one_is_documented(tmp_path):
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    problem = signorini.ContactProblem.from_qp(K, np.array([1.0, 1.0]), np.eye(2), np.array([0.1, 2.0]))
    out = record(signorini.solve(problem, "pdas"))
    assert out["units"]["system"].startswith("the QP's")
    problem.save(tmp_path / "p.npz")
    saved = record(signorini.solve(signorini.ContactProblem.load(tmp_path / "p.npz"), "qp-osqp"))
    assert undocumented(key_paths(out) | key_paths(saved)) == set()


@pytest.mark.slow
def test_every_key_of_a_failed_and_an_adaptive_solve_is_documented():
    failed = record(signorini.solve("block", "uzawa", params={"nx": 6, "ny": 6}, max_iter=1))
    adaptive = record(signorini.solve_adaptive("hertz-cylinder", 0.05))
    assert adaptive["extras"]["adaptive"]
    assert undocumented(key_paths(failed) | key_paths(adaptive)) == set()


def test_every_key_the_cli_writes_is_documented(tmp_path, capsys):
    path = tmp_path / "out.json"
    scene = DOC.parents[1] / "examples" / "hertz-cylinder.toml"
    assert main(["solve", str(scene), "--set", "n_contact=10", "--json", str(path)]) in (0, 1)
    out = json.loads(path.read_text())
    assert out["schema_version"] == SCHEMA_VERSION and out["scene"] == "hertz-cylinder"
    assert undocumented(key_paths(out)) == set()


def test_every_key_of_a_solve_of_a_problem_file_is_documented(tmp_path, capsys):
    path = tmp_path / "qp.npz"
    np.savez(path, K=np.array([[2.0, -1.0], [-1.0, 2.0]]), f=np.array([1.0, 1.0]), N=np.eye(2),
             d=np.array([0.1, 2.0]))
    assert main(["solve", str(path), "--json", str(tmp_path / "out.json")]) == 0
    out = json.loads((tmp_path / "out.json").read_text())
    assert out["units"]["system"].startswith("the QP's")
    assert undocumented(key_paths(out)) == set()


def test_every_key_of_a_crosscheck_is_documented():
    out = json.loads(to_json(crosscheck("block", ["pdas", "qp-clarabel"],
                                        params={"nx": 6, "ny": 6}).to_dict()))
    assert out["schema_version"] == SCHEMA_VERSION and out["units"]
    assert undocumented(key_paths(out)) == set()


@pytest.mark.slow
def test_every_key_of_a_validation_report_is_documented(tmp_path, capsys):
    """Two built-in cases and a user's problem file, an exact and an iterative method."""
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    np.savez(tmp_path / "mine.npz", K=K, f=np.array([2.0, 1.0]), N=np.eye(2), d=np.array([0.5, 1.0]))
    code = main(["validate", "--case", "block", "--case", "hertz-cylinder-coarse",
                 "--problem", str(tmp_path / "mine.npz"), "--method", "pdas", "--method", "uzawa",
                 "--out", str(tmp_path / "report")])
    capsys.readouterr()
    assert code in (0, 1)
    out = json.loads((tmp_path / "report" / "report.json").read_text())
    assert out["schema_version"] == SCHEMA_VERSION
    assert {"checks[].name", "runs[].kkt.primal", "limits.hertz_a_rel"} <= key_paths(out)
    assert undocumented(key_paths(out)) == set()
