"""One door: a solve runs one pipeline, read top to bottom, traced with ``sys.setprofile``.

``signorini.solve`` checks the request once, matches a target load by load control (only when
there is one), runs the method and certifies its answer once; ``signorini solve`` hands the
request it checked to that pipeline. The package files a solve enters are counted, so that a
detour back through the layers, or a module entered with nothing to do, shows up as a larger
count (the bounds are what the pipeline enters today: a regression guard, not the aim of 20
files for a scene and 8 for a QP of one's own). Read with ``ast``: nothing outside the registry
branches on a method's name, and no module keeps state in a module-level dict, list or set.
"""

from __future__ import annotations

import ast
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import signorini
from signorini.api import check_request
from signorini.cli import main

ROOT = os.path.dirname(signorini.__file__)
#: package files a solve enters: a scene with a target load, and a QP given as arrays
SCENE_FILES = 27
QP_FILES = 10


def traced(step):
    """What ``step()`` returned, the package files it entered and its calls of check_request
    and of the KKT certificate."""
    files: set[str] = set()
    calls = {"check_request": 0, "certificate": 0}
    checking = os.path.join(ROOT, "solvers", "registry.py")
    certifying = os.path.join(ROOT, "certification", "kkt.py")

    def profile(frame, event, arg):
        if event != "call" or not frame.f_code.co_filename.startswith(ROOT):
            return
        where, name = frame.f_code.co_filename, frame.f_code.co_name
        files.add(where)
        if (where, name) == (checking, "check_request"):
            calls["check_request"] += 1
        elif (where, name) == (certifying, "certificate"):
            calls["certificate"] += 1

    sys.setprofile(profile)
    try:
        result = step()
    finally:
        sys.setprofile(None)
    return result, files, calls


def own_qp():
    return signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),
                                            N=np.array([[1.0, 0.0]]), d=np.array([0.25]))


@pytest.mark.parametrize("make, bound", [(lambda: "hertz-cylinder", SCENE_FILES),
                                         (own_qp, QP_FILES)], ids=["scene", "from_qp"])
def test_one_solve_checks_once_certifies_once_and_enters_few_files(make, bound):
    signorini.solve(make(), "pdas")  # first imports and caches are not the pipeline's
    problem = make()
    result, files, calls = traced(lambda: signorini.solve(problem, "pdas"))
    assert result.converged, result.message
    assert calls == {"check_request": 1, "certificate": 1}
    assert len(files) <= bound, sorted(os.path.relpath(f, ROOT) for f in files)


def test_the_trace_counts_a_second_door():
    """The counts are not blind: two solves check twice and certify twice."""
    problem = own_qp()
    (first, second), _, calls = traced(lambda: (signorini.solve(problem, "pdas"),
                                                 signorini.solve(problem, "pdas")))
    assert first.converged and second.converged
    assert calls == {"check_request": 2, "certificate": 2}


def test_the_command_line_checks_the_request_once(capsys):
    """``signorini solve`` checks the method, tolerance and options before it builds the scene,
    and the solve takes that checked request: one check, one certificate."""
    main(["solve", "hertz-cylinder", "--method", "pdas"])  # first imports are not the pipeline's
    code, _, calls = traced(lambda: main(["solve", "hertz-cylinder", "--method", "pdas",
                                          "--tol", "1e-9", "--opt", "c=2"]))
    assert code == 0, capsys.readouterr()
    assert calls == {"check_request": 1, "certificate": 1}


def test_a_checked_request_is_not_checked_again_nor_given_twice():
    request = check_request("pdas", 1e-9, None, {})
    result, _, calls = traced(lambda: signorini.solve(own_qp(), request))
    assert result.converged and calls["check_request"] == 0
    with pytest.raises(signorini.InputError, match="check_request"):
        signorini.solve(own_qp(), request, tol=1e-6)


# -- read with ast ----------------------------------------------------------------------------

PACKAGE = Path(ROOT)
#: where a method's name may be compared: the registry, and the studies and reports whose rows
#: are runs of the methods they are about
NAMES_ALLOWED = ("solvers/registry.py", "studies/", "output/")


def name_branches(path: Path, names: set[str]) -> list[str]:
    """Comparisons of a method's or a solve's ``method``/``solved_by`` with a method's name."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.Compare):
            continue
        sides = [node.left, *node.comparators]
        constants = {e.value for side in sides
                     for e in (side.elts if isinstance(side, (ast.Tuple, ast.List, ast.Set)) else [side])
                     if isinstance(e, ast.Constant) and isinstance(e.value, str)}
        about_method = any("method" in ast.unparse(side) or "solved_by" in ast.unparse(side)
                           for side in sides if not isinstance(side, ast.Constant))
        if constants & names and about_method:
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


def test_nothing_outside_the_registry_branches_on_a_method_name(tmp_path):
    names = {method.name for method in signorini.methods()}
    found = {str(p.relative_to(PACKAGE)): name_branches(p, names)
             for p in sorted(PACKAGE.rglob("*.py"))
             if not str(p.relative_to(PACKAGE)).startswith(NAMES_ALLOWED)}
    assert {where: hits for where, hits in found.items() if hits} == {}
    planted = tmp_path / "planted.py"
    planted.write_text("def f(solved_by, spec):\n"
                       "    return solved_by == 'pdas-amg' or spec.method in ('auto', 'nested')\n")
    assert len(name_branches(planted, names)) == 2


#: containers a module may build once and never change: a read-only view is not a dict
MUTATORS = {"append", "extend", "insert", "pop", "popitem", "remove", "clear", "update",
            "setdefault", "add", "discard", "appendleft", "move_to_end"}
#: module-level state kept on purpose, each with its reason (a public registration API, the
#: outputs one command has written so far): not of the solve pipeline
STATE_ALLOWED = {("scenes/registry.py", "SCENES"), ("files.py", "_created"),
                 ("files.py", "_staged"), ("files.py", "_written")}


def module_state_changed(path: Path) -> list[tuple[str, str]]:
    """``(name, how)`` for each module-level dict, list or set that a function changes, and each
    ``global`` statement."""
    tree = ast.parse(path.read_text())
    containers = (ast.Dict, ast.List, ast.Set, ast.DictComp, ast.ListComp, ast.SetComp)
    def built(value) -> bool:
        called = value.func if isinstance(value, ast.Call) else None
        return isinstance(value, containers) or called is not None and ast.unparse(called).split(
            "[")[0] in ("dict", "list", "set", "collections.OrderedDict", "defaultdict", "deque")

    state = set()
    for node in tree.body:
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, ast.AnnAssign) else []
        for target in targets:
            pairs = zip(target.elts, value.elts) if isinstance(target, ast.Tuple) and \
                isinstance(value, ast.Tuple) else [(target, value)]
            state |= {name.id for name, each in pairs if isinstance(name, ast.Name) and built(each)}
    found = []
    for function in ast.walk(tree):
        if not isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for node in ast.walk(function):
            if isinstance(node, ast.Global):
                found += [(name, "global") for name in node.names]
            elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and isinstance(node.func.value, ast.Name) and node.func.value.id in state \
                    and node.func.attr in MUTATORS:
                found.append((node.func.value.id, node.func.attr))
            elif isinstance(node, (ast.Assign, ast.AugAssign, ast.Delete)):
                targets = node.targets if not isinstance(node, ast.AugAssign) else [node.target]
                found += [(t.value.id, "item") for t in targets if isinstance(t, ast.Subscript)
                          and isinstance(t.value, ast.Name) and t.value.id in state]
    return found


def test_no_module_keeps_state_that_its_functions_change(tmp_path):
    found = {(str(p.relative_to(PACKAGE)), name): how for p in sorted(PACKAGE.rglob("*.py"))
             for name, how in module_state_changed(p)}
    assert {key: how for key, how in found.items() if key not in STATE_ALLOWED} == {}
    planted = tmp_path / "planted.py"
    planted.write_text("CALLABLES: dict = {}\nLIMIT, SEEN = 3, set()\n_last = None\n\n"
                       "def remember(name, method):\n    CALLABLES[name] = method\n"
                       "    SEEN.add(name)\n    global _last\n    _last = name\n")
    assert sorted(module_state_changed(planted)) == [("CALLABLES", "item"), ("SEEN", "add"),
                                                     ("_last", "global")]


def test_the_registry_is_read_only():
    from signorini.solvers.registry import REGISTRY
    from signorini.solvers.options import TABLE

    for table in (REGISTRY, TABLE):
        with pytest.raises(TypeError):
            table["mine"] = table[next(iter(table))]


def test_the_qp_is_the_qp_alone_and_its_model_makes_it():
    """ContactProblem holds the QP and reaches into no other record; the model (mesh, parameters,
    load family) is ``problem.model``, and a QP given as arrays has the empty one."""
    scene = signorini.build_problem("hertz-cylinder", params={"n_contact": 16, "grading": 0.4})
    for name in ("mesh", "params", "push", "pending", "basis", "expand", "applied_load", "dofs",
                 "reference", "reference_data", "axisymmetric", "discretisation"):
        assert not hasattr(scene, name), name
    assert scene.model.pending and scene.model.mesh is not None
    model, f, d = scene.model.at_push(2.0 * scene.model.push.scale)  # the affine load family
    assert not model.pending and model.mesh is scene.model.mesh
    assert np.allclose(d - scene.model.push.d0, 2.0 * (scene.d - scene.model.push.d0))
    moved = scene.pushed(2.0 * scene.model.push.scale)
    assert np.shares_memory(moved.K.data, scene.K.data)  # K and its factorisation are shared
    assert np.array_equal(moved.f, f) and np.array_equal(moved.d, d)
    own = own_qp()
    assert own.model.empty and own.model.mesh is None and not own.model.pending
    assert np.array_equal(own.model.expand(np.arange(2.0)), np.arange(2.0))
