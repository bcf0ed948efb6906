"""Shared fixtures."""

from __future__ import annotations

import pytest


@pytest.fixture
def saved_figures(monkeypatch):
    """Every matplotlib figure saved while the test runs, in order: a figure test can then check
    what it shows (axes, legend, the plotted data), not only that a file was written."""
    from matplotlib.figure import Figure

    saved = []
    original = Figure.savefig

    def record(self, *args, **kwargs):
        saved.append(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    return saved


@pytest.fixture(scope="session")
def docs_site(tmp_path_factory):
    """The documentation site built once with ``mkdocs build --strict``, the tutorials executed in it.

    Returns the finished build (its return code and messages) and the site's folder. The build
    executes every notebook of docs/tutorials in a fresh kernel, so the tests of the site and of the
    tutorials share one execution.
    """
    import os
    import subprocess
    import sys
    from pathlib import Path

    for module in ("mkdocs", "material", "mkdocstrings_handlers.python", "mkdocs_jupyter"):
        pytest.importorskip(module, reason=f"the docs extra builds the site ({module})")
    root = Path(__file__).resolve().parents[1]
    site = tmp_path_factory.mktemp("docs") / "site"
    env = {**os.environ, "MPLBACKEND": "module://matplotlib_inline.backend_inline",
           "SIGNORINI_DOCS_EXECUTE": "true"}
    built = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                           cwd=root, capture_output=True, text=True, timeout=1200, env=env)
    return built, site
