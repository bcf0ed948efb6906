"""Import only what a command uses: ``import signorini`` loads the package alone (its names load
at first use); the public API and ``signorini solve block`` load no plotting, no QP backend and
no ``scipy.spatial`` (only meshing with Delaunay and the k-d tree lookups need it); the number
of modules the public API adds is held under a bound.

Each check runs in a fresh interpreter (this one has imported everything by now).
"""

from __future__ import annotations

import json
import subprocess
import sys

from test_startup import HEAVY

#: what neither ``import signorini`` nor a solve of the block may load
NOT_ON_IMPORT = HEAVY + ("scipy.spatial", "rich")

#: what ``import signorini`` and ``signorini --help`` leave to the first use of a name
LAZY = ("numpy", "scipy", "skfem", "triangle", "signorini.api", "signorini.solvers.registry")

#: modules the public API (``import signorini; signorini.solve``) may add to a fresh interpreter. Measured with
#: ``python -c "import sys; b = set(sys.modules); import signorini; print(len(set(sys.modules) - b))"``
#: on Python 3.11, NumPy 2.4, SciPy 1.17, scikit-fem 12: 641 modules (740 while scipy.spatial and
#: scipy.io were imported up front), and about 10 % more is allowed for other versions.
MAX_MODULES = 705


def run(args: list[str]) -> subprocess.CompletedProcess:
    proc = subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc


def added_by_import(statements: str = "import signorini\nsignorini.solve") -> set[str]:
    """The modules ``statements`` (by default: the public API) add to a fresh interpreter."""
    proc = run(["-c", f"import json, sys\nbefore = set(sys.modules)\n{statements}\n"
                      "print(json.dumps(sorted(set(sys.modules) - before)))"])
    return set(json.loads(proc.stdout.strip().splitlines()[-1]))


def imported_by(stderr: str) -> set[str]:
    """The module names of ``python -X importtime``'s report (``import time: self | total | name``)."""
    return {line.split("|")[-1].strip() for line in stderr.splitlines()
            if line.startswith("import time:") and not line.rstrip().endswith("package")}


def loaded(modules: set[str], names=NOT_ON_IMPORT) -> list[str]:
    """Those of ``names`` that ``modules`` holds, itself or any of its submodules."""
    return [name for name in names if any(m == name or m.startswith(name + ".") for m in modules)]


def test_import_signorini_loads_the_package_alone():
    added = added_by_import("import signorini")
    assert "signorini" in added and loaded(added, LAZY) == []


def test_the_cli_help_loads_no_numerics():
    added = added_by_import("import contextlib, io\nfrom signorini.cli import main\n"
                            "with contextlib.redirect_stdout(io.StringIO()) as out:\n"
                            "    with contextlib.suppress(SystemExit):\n"
                            "        main(['solve', '--help'])\n"
                            "assert '--method' in out.getvalue()")
    assert "signorini.cli.solve" in added
    assert loaded(added, LAZY) in ([], ["numpy"])  # numpy: the options' checks read its types


def test_the_public_api_loads_no_backend_plotting_or_spatial():
    added = added_by_import()
    assert "signorini.api" in added  # the public API is what was imported
    assert loaded(added) == []


def test_import_signorini_adds_a_bounded_number_of_modules():
    added = added_by_import()
    assert len(added) <= MAX_MODULES, (
        f"import signorini adds {len(added)} modules, more than {MAX_MODULES}: run "
        "python -X importtime -c 'import signorini' to see which import grew")


def test_solving_the_block_loads_no_plotting_backend_or_spatial():
    proc = run(["-X", "importtime", "-m", "signorini.cli", "solve", "block", "--json", "-"])
    record = json.loads(proc.stdout)
    assert record["status"] == "converged"
    modules = imported_by(proc.stderr)
    assert "signorini.fem.assembly" in modules  # the report covers the whole command
    assert loaded(modules) == []


def test_importtime_report_is_read_by_name():
    """The reader of ``-X importtime`` finds nested modules and skips the header line."""
    report = ("import time: self [us] | cumulative | imported package\n"
              "import time:       120 |        120 |     scipy.spatial._kdtree\n"
              "import time:       300 |        420 |   scipy.spatial\n")
    modules = imported_by(report)
    assert modules == {"scipy.spatial._kdtree", "scipy.spatial"}
    assert loaded(modules) == ["scipy.spatial"]
