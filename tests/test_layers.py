"""The package's imports run one way, low layer to high, with no cycle (read with ``ast``).

Layers, low to high (a module may import its own layer and the layers below):

0. ``errors``, ``files``, ``reprs``     exceptions, atomic writes, short reprs
1. ``numerics``                          factorisations, dense LCP, zone kernel, the push kernel
2. ``problem``, ``certification``, ``references``, ``fem``  the QP and its answer, judging it,
   analytic references and pressure, the finite elements
3. ``solvers``                           the registry collects each backend's METHODS
4. ``load_control``                      load control: the one driver around any method
5. ``scenes``                            families, meshing, scene files, building problems
6. ``api``, ``result``, ``crosschecking``, ``derivatives``, the package: the public Python API
7. ``studies``, ``output`` one runner and its studies; reports, plots, export
8. ``cli``                               parsing only

Beyond the order, the data flow: scenes import no solver and no load control (building a
scene solves nothing), solvers know no physics (no analytic reference, no mesh, no scene),
fem imports nothing that solves (no solver, scene, load control, zone or push kernel), and
output imports no study.

Imports of the package's own modules sit at the top of a module; one inside a
function is allowed only in ``cli/`` (each command loads what it needs, so
that ``signorini methods`` does not start matplotlib) and must carry a comment
saying why.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "signorini"

LAYERS = {
    "errors": 0, "files": 0, "paths": 0, "reprs": 0,
    "numerics": 1,
    "problem": 2, "certification": 2, "references": 2, "fem": 2,
    "solvers": 3,
    "load_control": 4,
    "scenes": 5,
    "api": 6, "result": 6, "crosschecking": 6, "crosscheck_tables": 6, "derivatives": 6, "": 6,
    "studies": 7, "output": 7,
    "cli": 8,
}
#: (package part, what it must not import): the data flow, beyond the order of the layers
FORBIDDEN = [
    ("signorini.scenes", ("signorini.solvers", "signorini.load_control")),
    ("signorini.solvers", ("signorini.references", "signorini.fem", "signorini.scenes")),
    ("signorini.fem", ("signorini.solvers", "signorini.scenes", "signorini.load_control",
                       "signorini.numerics.zone", "signorini.numerics.push")),
    ("signorini.output", ("signorini.studies",)),
]
#: the package whose modules may import the package's own modules inside functions (with a comment)
LAZY_ALLOWED = "signorini.cli"
MAX_LINES = 400


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def resolve(module: str, node: ast.ImportFrom | ast.Import) -> list[str]:
    """The package modules an import statement loads (a name may be a submodule)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "signorini"]
    base = node.module or ""
    if node.level:
        package = module.split(".") if MODULES[module].name == "__init__.py" else module.split(".")[:-1]
        package = package[:len(package) - node.level + 1]
        base = ".".join(package + ([node.module] if node.module else []))
    if base.split(".")[0] != "signorini":
        return []
    targets = []
    for alias in node.names:
        candidate = f"{base}.{alias.name}"
        targets.append(candidate if candidate in MODULES else base)
    return targets


def imports(module: str) -> list[tuple[str, int, bool]]:
    """(imported module, line, inside a function) for every package import of ``module``."""
    tree = ast.parse(MODULES[module].read_text())
    found = []

    def visit(node: ast.AST, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inner = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                found.extend((target, child.lineno, in_function) for target in resolve(module, child))
            visit(child, inner)

    visit(tree, False)
    return found


def layer(module: str) -> int:
    parts = module.split(".")
    key = parts[1] if len(parts) > 1 else ""
    assert key in LAYERS, f"{module} is in no layer: add it to LAYERS in {__file__}"
    return LAYERS[key]


def test_every_module_has_a_layer():
    for module in MODULES:
        layer(module)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_imports_run_down_the_layers(module):
    upward = [(target, line) for target, line, _ in imports(module) if layer(target) > layer(module)]
    assert not upward, f"{module} imports up the layers: {upward}"


@pytest.mark.parametrize("part, forbidden", FORBIDDEN, ids=[part for part, _ in FORBIDDEN])
def test_imports_follow_the_data_flow(part, forbidden):
    found = [(module, target, line) for module in sorted(MODULES)
             if module == part or module.startswith(part + ".")
             for target, line, _ in imports(module)
             if any(target == f or target.startswith(f + ".") for f in forbidden)]
    assert not found, f"{part} imports what it must not: {found}"


def test_the_data_flow_rules_can_fail():
    """The rule's matcher sees a real import: the api imports load control."""
    assert any(t == "signorini.load_control" for t, _, _ in imports("signorini.api"))


@pytest.mark.parametrize("module", sorted(MODULES))
def test_package_imports_sit_at_the_top(module):
    lines = MODULES[module].read_text().splitlines()
    lazy = [(target, line) for target, line, inner in imports(module) if inner]
    if module != LAZY_ALLOWED and not module.startswith(LAZY_ALLOWED + "."):
        assert not lazy, f"{module} imports package modules inside functions: {lazy}"
        return
    for target, line in lazy:
        said = lines[line - 1] + lines[line - 2]
        assert "#" in said, f"{module}:{line} imports {target} inside a function without saying why"


def test_no_import_cycle():
    graph = {m: {t for t, _, _ in imports(m) if t in MODULES and t != m} for m in MODULES}
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycle = path[path.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " → ".join(cycle))
            if nxt not in state:
                visit(nxt)
        path.pop()
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_modules_are_small(module):
    count = len(MODULES[module].read_text().splitlines())
    assert count <= MAX_LINES, f"{module} has {count} lines (at most {MAX_LINES}): split it"


def test_the_resolver_sees_imports():
    """The resolver is not blind: problem/contact.py's own imports include lower layers' modules."""
    targets = {t for t, _, _ in imports("signorini.problem.contact")}
    assert "signorini.numerics.factor" in targets and "signorini.errors" in targets


#: the modules that own scene parameters by name (the scene families and scene files); every
#: other module reads typed fields
PARAMETER_OWNERS = ("signorini.scenes",)


def parameter_reads(source: str) -> list[int]:
    """Lines that read a parameter by name: ``params[…]`` or ``params.get(…)`` on a name
    ``params``, an attribute ``….params`` or a name bound to one (``p = problem.model.params``).
    Writing one (``params[k] = v``, a dict built for a scene) is not a read; ``+=`` is."""
    tree = ast.parse(source)
    aliases = {"params"} | {target.id for node in ast.walk(tree) if isinstance(node, ast.Assign)
                            and isinstance(node.value, ast.Attribute) and node.value.attr == "params"
                            for target in node.targets if isinstance(target, ast.Name)}
    augmented = {id(node.target) for node in ast.walk(tree) if isinstance(node, ast.AugAssign)}

    def is_params(node: ast.AST) -> bool:
        return (isinstance(node, ast.Name) and node.id in aliases) or \
            (isinstance(node, ast.Attribute) and node.attr == "params")

    return sorted(node.lineno for node in ast.walk(tree)
                  if isinstance(node, ast.Subscript) and is_params(node.value)
                  and (isinstance(node.ctx, ast.Load) or id(node) in augmented)
                  or isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                  and node.func.attr == "get" and is_params(node.func.value))


@pytest.mark.parametrize("module", sorted(m for m in MODULES if not any(
    m == owner or m.startswith(owner + ".") for owner in PARAMETER_OWNERS)))
def test_scene_parameters_are_read_by_typed_fields(module):
    lines = parameter_reads(MODULES[module].read_text())
    assert not lines, (
        f"{module} reads scene parameters by name (lines {lines}): read the typed record instead "
        "(Model.reference, Model.push's delta and P, SceneModel's fields), "
        "which the scene family builds from its parameters")


def test_the_parameter_rule_can_fail():
    """The matcher sees reads by name, through an alias too, and lets writes be."""
    assert parameter_reads("E = problem.model.params['E']\nR = params.get('R')\n") == [1, 2]
    assert parameter_reads("p = problem.model.params\nx = p['half_length']\nparams['P'] *= 2\n") == [2, 3]
    assert parameter_reads("params['delta'] = 1.0\nbuild(params={'E': 1.0})\nd = dict(params)\n") == []
