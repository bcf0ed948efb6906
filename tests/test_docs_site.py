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
def test_the_site_builds_strictly(tmp_path):
    pytest.importorskip("mkdocs")
    pytest.importorskip("material")
    pytest.importorskip("mkdocstrings_handlers.python")
    built = mkdocs_build(ROOT / "mkdocs.yml", tmp_path / "site")
    assert built.returncode == 0, built.stderr[-4000:]
    api = (tmp_path / "site" / "api" / "index.html").read_text(encoding="utf-8")
    for name in ("solve", "build_problem", "certificate", "crosscheck", "Result"):
        assert f'id="signorini.{name}"' in api, f"the API reference lacks signorini.{name}"
    assert (tmp_path / "site" / "tutorials" / "01-two-contact-points.ipynb").is_file()


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


def test_every_nav_entry_is_a_page():
    """mkdocs.yml's nav names only pages that exist (--strict fails on one that does not)."""
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8").split("\nnav:\n", 1)[1]
    pages = re.findall(r"^\s*- [^:#]+: (\S+\.md)$", nav, flags=re.M)
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
