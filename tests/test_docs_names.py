"""Every ``signorini.<module>.<name>`` the README, the docs, the tutorials and the docstrings cite exists.

A moved or renamed function leaves a dotted name behind in prose that no
import checks (the layout change of issue 12 found ``signorini.solvers.solve``
cited in three places, where it raised ImportError); this test resolves each
one by importing the longest module prefix and walking the attributes.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOTTED = re.compile(r"(?<!//)\bsignorini(?:\.[A-Za-z_][A-Za-z0-9_]*)+")  # not a host in a URL
FILE_ENDINGS = (".py", ".toml", ".json", ".md", ".msh", ".png", ".csv", ".vtu", ".npz")


def sources() -> list[Path]:
    return ([ROOT / "README.md"] + sorted((ROOT / "docs").rglob("*.md"))
            + sorted((ROOT / "docs" / "tutorials").rglob("*.ipynb"))  # the tutorials and their solutions
            + sorted((ROOT / "signorini").rglob("*.py")))


def resolves(name: str) -> bool:
    parts = name.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def cited() -> dict[str, list[str]]:
    names: dict[str, list[str]] = {}
    for path in sources():
        for name in set(DOTTED.findall(path.read_text(encoding="utf-8"))):
            if not name.endswith(FILE_ENDINGS):
                names.setdefault(name, []).append(str(path.relative_to(ROOT)))
    return names


def test_every_cited_name_exists():
    missing = {name: where for name, where in cited().items() if not resolves(name)}
    assert not missing, f"names cited but not importable: {missing}"


def test_the_check_catches_a_missing_name():
    assert resolves("signorini.certification.kkt.certificate")
    assert not resolves("signorini.solvers.solve")
    assert not resolves("signorini.no_such_module.thing")



PATH_CITED = re.compile(r"\bsignorini/[A-Za-z0-9_/]+\.py\b")


def test_every_cited_source_file_exists():
    missing = {}
    for path in sources():
        for cited_path in set(PATH_CITED.findall(path.read_text(encoding="utf-8"))):
            if not (ROOT / cited_path).is_file():
                missing.setdefault(cited_path, []).append(str(path.relative_to(ROOT)))
    assert not missing, f"source files cited but absent: {missing}"
