"""The package as a user gets it: the metadata, the install hints, the sdist and the wheel.

The slow tests build the sdist and, from it, the wheel (``python -m build``, which fetches
setuptools into its own build environment), install the wheel into a clean virtual
environment (no system site-packages, not this one's) and run the installed command from a
folder outside the repository. The wheel's dependencies come from a wheelhouse kept between
runs (``SIGNORINI_WHEELHOUSE``, default ``~/.cache/signorini-wheelhouse``): the install is
tried from it alone (``--no-index``, offline), and only when something is missing is it
filled by ``pip download`` from the package index.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

import signorini
from signorini.errors import DISTRIBUTIONS, install_hint
from signorini.numerics.factor import _MODULES as FACTOR_MODULES, EXTRAS as FACTOR_EXTRAS
from signorini.solvers.registry import methods

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
EXTRAS = PYPROJECT["project"]["optional-dependencies"]


def requirement_name(requirement: str) -> str:
    return re.split(r"[\s<>=!~;\[]", requirement, maxsplit=1)[0].lower().replace("_", "-")


def installed_by(extra: str) -> set[str]:
    """The distributions ``pip install 'signorini[extra]'`` installs (self-references followed)."""
    names: set[str] = set()
    for requirement in EXTRAS[extra]:
        inner = re.fullmatch(r"signorini\[(.+)\]", requirement.strip())
        if inner:
            for other in inner.group(1).split(","):
                names |= installed_by(other.strip())
        else:
            names.add(requirement_name(requirement))
    return names


def distribution(module: str) -> str:
    return DISTRIBUTIONS.get(module, module).lower()


# --- metadata ---------------------------------------------------------------------------------


def test_the_licence_is_mit_with_its_file_and_the_build_backend_can_read_it():
    project = PYPROJECT["project"]
    assert project["license"] == "MIT"
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License") and "the signorini developers" in text
    assert "LICENSE" in project["license-files"]
    # an SPDX string as license needs setuptools 77 or later
    (setuptools,) = [r for r in PYPROJECT["build-system"]["requires"] if r.startswith("setuptools")]
    assert tuple(int(x) for x in re.search(r">=\s*([\d.]+)", setuptools).group(1).split(".")) >= (77,)


def test_the_package_says_it_is_typed():
    assert (ROOT / "signorini" / "py.typed").is_file()
    assert "py.typed" in PYPROJECT["tool"]["setuptools"]["package-data"]["signorini"]


# --- install hints ----------------------------------------------------------------------------


@pytest.mark.parametrize("method", methods(), ids=lambda m: m.name)
def test_each_methods_hint_installs_what_it_needs(method):
    hint = method.install_hint
    extra = re.fullmatch(r"pip install 'signorini\[(\w+)\]'", hint)
    needed = {distribution(m) for m in method.requires}
    if extra:
        assert needed <= installed_by(extra.group(1)) | {"qpsolvers"}, hint
    else:
        assert set(hint.removeprefix("pip install ").split()) <= needed, hint


@pytest.mark.parametrize("backend", sorted(FACTOR_EXTRAS))
def test_each_factorisation_backends_extra_installs_it(backend):
    assert distribution(FACTOR_MODULES[backend]) in installed_by(FACTOR_EXTRAS[backend])


def test_every_extra_a_message_names_exists():
    named = set()
    for path in (ROOT / "signorini").rglob("*.py"):
        named |= set(re.findall(r"signorini\[(\w+)\]", path.read_text()))
    assert named and named <= set(EXTRAS), named - set(EXTRAS)


def test_the_default_install_holds_what_the_default_methods_use_and_no_more():
    default = {requirement_name(r) for r in PYPROJECT["project"]["dependencies"]}
    for method in methods():
        if not method.install_hint.startswith("pip install 'signorini["):
            assert {distribution(m) for m in method.requires} <= default | {"qpsolvers"}, method.name
    # cvxpy without its bundled solvers: SCS and HiGHS are extras, and `all` brings every backend
    assert "cvxpy-base" in default and not {"cvxpy", "scs", "highspy"} & default
    assert {"scs", "highspy", "ecos"} <= installed_by("all")


def test_the_metadata_points_to_the_docs_site_messages_name():
    from signorini.errors import DOCS_SITE

    assert PYPROJECT["project"]["urls"]["Documentation"] == DOCS_SITE
    site = re.search(r"^site_url: (\S+)$", (ROOT / "mkdocs.yml").read_text(), re.M)
    assert site and site.group(1) == DOCS_SITE
    for url in PYPROJECT["project"]["urls"].values():  # each names a page of the site
        page = url.removeprefix(DOCS_SITE).strip("/")
        assert url.startswith(DOCS_SITE) and (not page or (ROOT / "docs" / f"{page}.md").is_file())


def test_a_hint_without_an_extra_names_the_pip_distributions():
    assert install_hint("", ["sksparse", "osqp"]) == "pip install scikit-sparse osqp"
    assert install_hint("gurobi", ["gurobipy"]) == "pip install 'signorini[gurobi]'"


# --- the sdist, the wheel, a clean environment -------------------------------------------------


def run(*command: str | Path, cwd: Path | None = None, check: bool = True) -> subprocess.CompletedProcess:
    done = subprocess.run([str(c) for c in command], cwd=cwd, capture_output=True, text=True,
                          env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
    if check and done.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, command))} exited {done.returncode}:\n"
                             f"{done.stdout[-2000:]}\n{done.stderr[-4000:]}")
    return done


@pytest.fixture(scope="module")
def dists(tmp_path_factory) -> dict[str, Path]:
    """The sdist, and the wheel built from it (as ``python -m build`` does by default)."""
    pytest.importorskip("build", reason="pip install 'signorini[test]' (the build front end)")
    out = tmp_path_factory.mktemp("dist")
    run(sys.executable, "-m", "build", "--outdir", out, ROOT)
    (sdist,), (wheel,) = out.glob("*.tar.gz"), out.glob("*.whl")
    return {"sdist": sdist, "wheel": wheel}


@pytest.fixture(scope="module")
def installed(dists, tmp_path_factory) -> Path:
    """The ``bin`` folder of a clean virtual environment with the wheel installed."""
    venv = tmp_path_factory.mktemp("venv")
    run(sys.executable, "-m", "venv", "--without-pip", "--clear", venv)
    wheelhouse = Path(os.environ.get("SIGNORINI_WHEELHOUSE",
                                     Path.home() / ".cache" / "signorini-wheelhouse"))
    wheelhouse.mkdir(parents=True, exist_ok=True)
    pip = [sys.executable, "-m", "pip", "--python", venv / "bin" / "python", "install",
           "--quiet", "--no-compile", "--no-index", "--find-links", wheelhouse, dists["wheel"]]
    if run(*pip, check=False).returncode != 0:  # the wheelhouse lacks something: fill it
        for stale in wheelhouse.glob("signorini-*"):  # an older build of the same name would be
            stale.unlink()  # taken for this one, and its dependencies for this one's
        run(sys.executable, "-m", "pip", "download", "--quiet", "--dest", wheelhouse, dists["wheel"])
        run(*pip)
    return venv / "bin"


@pytest.mark.slow
def test_the_sdist_holds_the_examples_the_tutorials_and_the_licence(dists):
    with tarfile.open(dists["sdist"]) as sdist:
        names = {name.split("/", 1)[1] for name in sdist.getnames() if "/" in name}
    folders = ("examples", "docs/tutorials", "docs/tutorials/solutions")
    wanted = {str(p.relative_to(ROOT)) for folder in folders
              for p in (ROOT / folder).iterdir() if p.is_file() and p.suffix in {".toml", ".msh", ".py",
                                                                                 ".ipynb"}}
    assert wanted and wanted <= names, wanted - names
    assert {"LICENSE", "README.md", "signorini/py.typed"} <= names


@pytest.mark.slow
def test_the_wheel_installs_into_a_clean_environment_and_solves(installed, dists, tmp_path):
    version = run(installed / "signorini", "--version", cwd=tmp_path).stdout
    assert version.split() == ["signorini", signorini.__version__]
    done = run(installed / "signorini", "solve", "hertz-cylinder", "--json", "out.json", cwd=tmp_path)
    assert "converged" in done.stdout and (tmp_path / "out.json").is_file()
    listing = run(installed / "signorini", "methods", cwd=tmp_path).stdout
    assert "pdas" in listing
    # the example scene files come with the sdist: run one from its unpacked folder
    with tarfile.open(dists["sdist"]) as sdist:
        sdist.extractall(tmp_path, filter="data")
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir()]
    done = run(installed / "signorini", "solve", "examples/hertz-cylinder.toml", "--set", "n_contact=20",
               cwd=folder)
    assert "converged" in done.stdout
    typed = run(installed / "python", "-c", "import importlib.resources as r; "
                "print(r.files('signorini').joinpath('py.typed').is_file())").stdout
    assert typed.strip() == "True"
    urls = run(installed / "python", "-c", "import importlib.metadata as m; "
               "print(m.metadata('signorini').get_all('Project-URL'))").stdout
    assert "Documentation, " + signorini.errors.DOCS_SITE in urls
