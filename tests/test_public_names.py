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
