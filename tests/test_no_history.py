"""The package's source says what the code does, not how it came to be.

Issue numbers, commit hashes and the stories of runs belong in docs/ (how a
constant was measured) and in the git history; a module under signorini/
states the rule and cites the docs page. This test catches the marks that
can be caught mechanically: ``issue 12``, ``commit 66f74ea`` and a bare
hexadecimal word of 7 to 40 digits that is not a number (a hash quoted
without the word "commit"). Upstream references such as ``osqp#790`` are
citations and stay.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MODULES = sorted((ROOT / "signorini").rglob("*.py"))

ISSUE = re.compile(r"\b[Ii]ssue \d+")
COMMIT = re.compile(r"\bcommit [0-9a-f]{7,}\b")
HEX_WORD = re.compile(r"\b[0-9a-f]{7,40}\b")
#: a word of hex digits that is a number: only decimal digits, or a float in e-notation (1e10000)
NUMBER = re.compile(r"\d+(e\d+)?")


def history_marks(text: str) -> list[str]:
    """The issue numbers, commit references and bare hashes in ``text``, as found."""
    marks = ISSUE.findall(text) + COMMIT.findall(text)
    for word in HEX_WORD.findall(text):
        if not NUMBER.fullmatch(word) and re.search(r"\d", word) and re.search(r"[a-f]", word):
            marks.append(word)
    return marks


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_issue_numbers_or_commit_hashes(path):
    marks = history_marks(path.read_text(encoding="utf-8"))
    assert not marks, (f"{path.relative_to(ROOT)} cites {marks}: say what the code does here, "
                       "and move how it was measured to docs/")


def test_the_check_catches_history():
    assert history_marks('"""Fixed for issue 12."""') == ["issue 12"]
    assert history_marks("# Issue 7's tolerance") == ["Issue 7"]
    assert history_marks("#: measured at signorini commit 66f74ea") == ["commit 66f74ea", "66f74ea"]
    assert history_marks("# since 4076ab2 the floor is 1e-14") == ["4076ab2"]
    assert history_marks("# " + "0123456789abcdef" * 2 + "01234567") != []  # a full 40-digit hash


def test_the_check_passes_numbers_and_citations():
    for text in ("POISSON = (0.3, 0.4999, 0.49999999999)", "tol = 1e10000", "x = 1234567",
                 "# OSQP: polishing can fail silently (osqp#790)", "# in a decade", "# a defaced facade",
                 "# the accepted issue: a facade", 'colour = "#4daf4a"'):
        assert history_marks(text) == [], text
