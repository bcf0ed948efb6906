"""Start-up: heavy optional backends are imported only when a method or a command needs them.

Each check runs in a fresh interpreter (this one has imported everything by now).
"""

import importlib.util
import json
import subprocess
import sys

import pytest

from signorini.numerics.factor import PARDISO_OVER_CHOLMOD_FROM, available_backends
from signorini.solvers.registry import methods

#: optional backends a plain solve or ``signorini methods`` must not import
HEAVY = ("cvxpy", "petsc4py", "mpi4py", "qpsolvers", "osqp", "clarabel", "matplotlib", "pyamg")


def fresh(code: str) -> dict:
    """Run ``code`` in a new interpreter; the JSON object it prints last is the answer."""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def loaded_after(statements: str, modules=HEAVY) -> str:
    """Code that runs ``statements`` and prints which of ``modules`` it imported."""
    return (f"import json, sys\n{statements}\n"
            f"print(json.dumps({{'loaded': [m for m in {tuple(modules)!r} if m in sys.modules]}}))")


def test_a_solve_imports_no_optional_backend():
    answer = fresh(loaded_after(
        "import signorini\n"
        "result = signorini.solve('hertz-cylinder', params={'n_contact': 16, 'grading': 0.4})\n"
        "assert result.status == 'converged', result.solution.message"))
    assert answer["loaded"] == []


@pytest.mark.skipif(not {"cholmod", "pardiso"} <= set(available_backends()),
                    reason="needs both CHOLMOD and PARDISO installed")
@pytest.mark.slow
def test_the_default_cylinder_is_factorised_without_pardiso():
    """Importing pypardiso and MKL costs 0.2 s: not worth it below PARDISO_OVER_CHOLMOD_FROM."""
    answer = fresh(loaded_after(
        "import signorini\n"
        "result = signorini.solve('hertz-cylinder')\n"
        f"assert result.problem.n < {PARDISO_OVER_CHOLMOD_FROM}, result.problem.n",
        modules=HEAVY + ("pypardiso",)))
    assert answer["loaded"] == []


def test_a_2d_contact_zone_is_predicted_without_scipy_spatial():
    """scipy.spatial (a second of imports on a loaded machine) finds 3D candidates' spacing only."""
    answer = fresh(loaded_after(
        "import numpy as np\n"
        "from signorini.numerics.zone import zone_around_points\n"
        "x = np.linspace(0.0, 1.0, 200)\n"
        "assert zone_around_points(np.column_stack([x, 0 * x]), 0.3, 0.3) is not None",
        modules=("scipy.spatial",)))
    assert answer["loaded"] == []


def test_methods_lists_what_is_installed_without_importing_it():
    answer = fresh(
        "import contextlib, io, json, sys\n"
        "from signorini.cli import main\n"
        "out = io.StringIO()\n"
        "with contextlib.redirect_stdout(out):\n"
        "    main(['methods'])\n"
        f"loaded = [m for m in {HEAVY!r} if m in sys.modules]\n"
        "print(json.dumps({'loaded': loaded, 'lines': out.getvalue().splitlines()}))")
    assert answer["loaded"] == []
    listed = {line.split()[0]: line.split()[1] for line in answer["lines"][1:]}
    assert set(listed) == {m.name for m in methods()}
    for method in methods():
        installed = all(importlib.util.find_spec(module) is not None for module in method.requires)
        assert listed[method.name] == ("installed" if installed else "not"), method.name


def test_a_qp_given_as_arrays_loads_no_scene_mesher_or_finite_elements():
    """A QP of one's own has no mesh: solving it imports no scene family, mesher or scikit-fem
    (the package's folders load their contents at first use); a scene does import them."""
    meshing = ("skfem", "triangle", "signorini.scenes.build", "signorini.fem.assembly")
    answer = fresh(loaded_after(
        "import numpy as np, signorini\n"
        "qp = signorini.ContactProblem.from_qp(K=np.diag([2.0, 1.0]), f=np.ones(2),\n"
        "                                      N=np.array([[1.0, 0.0]]), d=np.array([0.25]))\n"
        "assert signorini.solve(qp, 'pdas').status == 'converged'", meshing))
    assert answer["loaded"] == []
    scene = fresh(loaded_after(
        "import signorini\n"
        "signorini.solve('hertz-cylinder', 'pdas', params={'n_contact': 16, 'grading': 0.4})",
        meshing))
    assert scene["loaded"] == list(meshing)  # the check sees the modules when they are loaded
