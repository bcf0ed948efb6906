"""Every package of signorini states its public names in ``__all__``, and each of them exists.

The names are read with ``ast`` (an ``__init__`` without ``__all__`` fails, whatever it
imports) and then looked up on the imported package; importing the packages starts no
plotting library and no optional solver backend.
"""

from __future__ import annotations

import ast
import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

from test_startup import HEAVY

PACKAGE = Path(__file__).resolve().parents[1] / "signorini"


def package_name(init: Path) -> str:
    return ".".join(init.parent.relative_to(PACKAGE.parent).parts)


PACKAGES = sorted(package_name(init) for init in PACKAGE.rglob("__init__.py"))


def declared(init: Path) -> list[str] | None:
    """The names an ``__init__.py`` assigns to ``__all__`` (None when it does not): a literal
    list, or the names a ``lazy_loader.attach(...)`` call lists literally, and what ``+=`` adds."""
    names = None
    for node in ast.parse(init.read_text()).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "__all__" for t in node.targets):
            names = [ast.literal_eval(element) for element in node.value.elts]
        elif (isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Tuple)
              and getattr(node.targets[0].elts[-1], "id", "") == "__all__"):
            call = node.value  # __getattr__, __dir__, __all__ = lazy_loader.attach(...)
            listed = {k.arg: ast.literal_eval(k.value) for k in call.keywords}
            names = list(listed.get("submodules", [])) + [
                name for attrs in listed.get("submod_attrs", {}).values() for name in attrs]
        elif isinstance(node, ast.AugAssign) and getattr(node.target, "id", "") == "__all__":
            names += ast.literal_eval(node.value)
    return names


def test_every_package_is_seen():
    assert {"signorini", "signorini.numerics", "signorini.fem", "signorini.solvers",
            "signorini.scenes", "signorini.studies", "signorini.studies.atlas", "signorini.output",
            "signorini.cli"} <= set(PACKAGES)


@pytest.mark.parametrize("name", PACKAGES)
def test_the_package_states_its_public_names(name):
    names = declared(PACKAGE.parent.joinpath(*name.split("."), "__init__.py"))
    assert names, f"{name}/__init__.py defines no __all__: list the package's public names"
    assert len(set(names)) == len(names), f"{name}.__all__ names one thing twice"
    module = importlib.import_module(name)
    assert not absent(module, names), f"{name}.__all__ names what the package lacks: {absent(module, names)}"


def absent(module, names: list[str]) -> list[str]:
    return [n for n in names if not hasattr(module, n)]


def test_the_checks_can_fail(tmp_path):
    """An ``__init__`` without ``__all__`` reads as None; a name the package lacks is seen."""
    (tmp_path / "__init__.py").write_text('"""A package."""\n\nfrom os import path\n')
    assert declared(tmp_path / "__init__.py") is None
    assert "solve" in declared(PACKAGE / "__init__.py")
    assert absent(importlib.import_module("signorini.solvers"), ["methods", "solve"]) == ["solve"]


def test_importing_the_packages_starts_no_heavy_backend():
    """The atlas draws figures (matplotlib); every other package imports without a backend."""
    light = [name for name in PACKAGES if not name.startswith("signorini.studies.atlas")]
    code = (f"import importlib, json, sys\nfor name in {light!r}:\n    importlib.import_module(name)\n"
            f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1]) == []


# -- every module: its public names in ``__all__``, and what other modules read of it listed --

MODULES = {".".join(p.with_suffix("").relative_to(PACKAGE.parent).parts): p
           for p in sorted(PACKAGE.rglob("*.py")) if p.name not in ("__init__.py", "__main__.py")}


def module_all(tree: ast.Module) -> list[str] | None:
    """The literal ``__all__`` of a module's syntax tree (None when it has none)."""
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "__all__" for t in node.targets):
            return ast.literal_eval(node.value)
    return None


def bound(tree: ast.Module) -> set[str]:
    """Every name a module binds at its top level (definitions, assignments, imports)."""
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            for target in node.targets if isinstance(node, ast.Assign) else [node.target]:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
    return names


def public_definitions(tree: ast.Module) -> list[str]:
    return [node.name for node in tree.body
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
            and not node.name.startswith("_")]


def read_from_others(modules: dict[str, Path]) -> dict[str, set[tuple[str, str]]]:
    """``{module: {(name, reader)}}``: the names each package module imports from another one,
    or reads as an attribute of it (``from signorini.solvers import pdas`` … ``pdas.METHODS``)."""
    read = {name: set() for name in modules}
    for reader, path in modules.items():
        tree, aliases = ast.parse(path.read_text()), {}
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module in modules:
                read[node.module] |= {(a.name, reader) for a in node.names}
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("signorini"):
                aliases |= {a.asname or a.name: f"{node.module}.{a.name}" for a in node.names
                            if f"{node.module}.{a.name}" in modules}
            elif isinstance(node, ast.Import):
                aliases |= {a.asname: a.name for a in node.names if a.name in modules and a.asname}
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and getattr(node.value, "id", None) in aliases:
                read[aliases[node.value.id]].add((node.attr, reader))
    return read


def unlisted(modules: dict[str, Path]) -> dict[str, list[str]]:
    """Per module, what breaks the rule: no ``__all__`` beside public definitions, a listed name
    it does not bind, or a name another package module reads that ``__all__`` does not list."""
    trees = {name: ast.parse(path.read_text()) for name, path in modules.items()}
    read = read_from_others(modules)
    found = {}
    for name, tree in trees.items():
        listed = module_all(tree)
        if listed is None:
            problems = [f"no __all__ ({d})" for d in public_definitions(tree)[:1]]
        else:
            problems = [f"lists unbound {n}" for n in listed if n not in bound(tree)]
            problems += [f"{reader} reads {n}" for n, reader in sorted(read[name])
                         if reader != name and n not in listed]
        if problems:
            found[name] = problems
    return found


def test_every_module_lists_its_public_names_and_what_others_read_of_it():
    assert unlisted(MODULES) == {}


def test_the_module_rule_can_fail(tmp_path):
    root = tmp_path / "signorini"
    root.mkdir()
    (root / "maker.py").write_text('__all__ = ["make", "gone"]\n\ndef make():\n    pass\n\n'
                                   'def _inner():\n    pass\n')
    (root / "user.py").write_text("from signorini.maker import _inner, make\n")
    (root / "bare.py").write_text("def open_door():\n    pass\n")
    modules = {f"signorini.{p.stem}": p for p in root.glob("*.py")}
    assert unlisted(modules) == {"signorini.maker": ["lists unbound gone",
                                                      "signorini.user reads _inner"],
                                 "signorini.bare": ["no __all__ (open_door)"]}
