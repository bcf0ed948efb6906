"""The documentation site builds with ``mkdocs build --strict``, and the README stays an introduction.

The site is docs/ (mkdocs.yml at the root: mkdocs-material, the API reference from the docstrings
through mkdocstrings). A broken link, a nav entry without its page or a docstring mkdocstrings
cannot render is a warning, and --strict turns it into a failed build.
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README_LINES = 200


def readme() -> str:
    return (ROOT / "README.md").read_text(encoding="utf-8")


def mkdocs_build(config: Path, site: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                           str(config), "--site-dir", str(site)],
                          cwd=ROOT, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_the_site_builds_strictly(docs_site):
    built, site = docs_site
    assert built.returncode == 0, built.stderr[-4000:]
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    for name in ("solve", "build_problem", "certificate", "crosscheck", "Result"):
        assert f'id="signorini.{name}"' in api, f"the API reference lacks signorini.{name}"
    assert (site / "tutorials" / "01-two-contact-points" / "01-two-contact-points.ipynb").is_file()


@pytest.mark.slow
def test_a_broken_link_fails_the_strict_build(tmp_path):
    """The check can fail: the same site with one link to a page that does not exist."""
    pytest.importorskip("mkdocs")
    pytest.importorskip("material")
    pytest.importorskip("mkdocstrings_handlers.python")
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# Home\n\nSee [the guide](no-such-page.md).\n", encoding="utf-8")
    config = tmp_path / "mkdocs.yml"
    config.write_text("site_name: probe\ntheme:\n  name: material\nnav:\n  - Home: index.md\n",
                      encoding="utf-8")
    built = mkdocs_build(config, tmp_path / "site")
    assert built.returncode != 0 and "no-such-page.md" in built.stderr


@pytest.mark.slow
def test_a_notebook_cell_that_raises_fails_the_build(tmp_path):
    """The check can fail: a notebook page whose cell raises, built as mkdocs.yml builds the tutorials."""
    for module in ("mkdocs", "material", "mkdocs_jupyter", "nbformat"):
        pytest.importorskip(module, reason=f"the docs extra builds the site ({module})")
    import nbformat

    plugin = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    assert "execute: !ENV [SIGNORINI_DOCS_EXECUTE, true]" in plugin and "allow_errors: false" in plugin
    docs = tmp_path / "docs"
    docs.mkdir()
    cell = nbformat.v4.new_code_cell("raise ValueError('a tutorial that no longer runs')")
    nbformat.write(nbformat.v4.new_notebook(cells=[cell], metadata={"kernelspec": {
        "name": "python3", "display_name": "Python 3", "language": "python"}}), docs / "broken.ipynb")
    config = tmp_path / "mkdocs.yml"
    config.write_text("site_name: probe\ntheme:\n  name: material\nnav:\n  - Broken: broken.ipynb\n"
                      "plugins:\n  - mkdocs-jupyter:\n      execute: true\n      allow_errors: false\n"
                      "      cache: false\n", encoding="utf-8")
    built = mkdocs_build(config, tmp_path / "site")
    assert built.returncode != 0 and "a tutorial that no longer runs" in built.stderr


def test_every_nav_entry_is_a_page():
    """mkdocs.yml's nav names only pages that exist (--strict fails on one that does not)."""
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8").split("\nnav:\n", 1)[1]
    pages = re.findall(r"^\s*- [^#\n]+: (\S+\.(?:md|ipynb))$", nav, flags=re.M)
    assert "index.md" in pages and "api.md" in pages
    missing = [page for page in pages if not (ROOT / "docs" / page).is_file()]
    assert not missing, f"nav entries without a page: {missing}"


def test_the_readme_introduces_in_at_most_200_lines():
    text = readme()
    assert len(text.splitlines()) <= README_LINES
    assert "<!-- generated:" not in text, "generated result blocks live on docs pages"
    for section in ("## Install", "## Three everyday commands", "## Python", "## Tutorials",
                    "## Where to go next"):
        assert f"\n{section}" in text, section
    assert "pip install -e '.[all]'" in text and "make test" in text
    assert len(re.findall(r"!\[[^\]]*\]\(([^)]+\.png)\)", text)) == 1, "one chart"


def test_every_readme_link_into_the_repository_exists():
    for target in re.findall(r"\]\(((?!https?:)[^)#]+)(?:#[^)]*)?\)", readme()):
        assert (ROOT / target).exists(), target


def test_the_pages_the_readme_moved_out_are_in_the_nav():
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    for page in ("guide.md", "maths.md", "methods.md", "results.md", "performance.md", "tutorials.md"):
        assert f": {page}\n" in nav, page


def test_mathjax_reads_the_notebooks_dollar_maths():
    """Notebook pages keep Jupyter's $ $ maths (arithmatex converts only the Markdown pages'):
    MathJax 3 must be configured for it before it loads, or the tutorials show raw TeX."""
    config = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    scripts = config.split("extra_javascript:\n", 1)[1].split("\n")
    assert scripts[0].startswith("  - javascripts/mathjax.js") and "mathjax@3" in scripts[1]
    mathjax = (ROOT / "docs" / "javascripts" / "mathjax.js").read_text(encoding="utf-8")
    assert '["$", "$"]' in mathjax and '["$$", "$$"]' in mathjax
