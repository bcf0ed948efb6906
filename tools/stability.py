"""The "When methods fail" blocks of docs/results.md, written from the committed stability atlas.

    .venv/bin/python tools/readme.py        # after `signorini stability --out docs`

``tables`` renders, from ``docs/stability/runs.json``: the run's headline (runs, time, the
package's record), the method × axis table of ``docs/stability.md`` (the same function draws
both: :func:`signorini.studies.atlas.report.method_axis_table`), and the findings, a paragraph per
axis that its module states (:attr:`signorini.studies.atlas.axis.Axis.headline`, with the helpers
of :mod:`signorini.studies.atlas.findings`). A finding also states things the numbers do not show
by themselves ("growth is never seen"); each such statement is checked against the rows, and
``tables`` raises :class:`StaleFinding` when a new run no longer shows it: rewrite the sentence in
its axis module, then run tools/readme.py. tests/test_readme_numbers.py holds that page to what
this writes.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from signorini.studies.atlas import AXES
from signorini.studies.atlas.findings import StaleFinding, findings, run_headline
from signorini.studies.atlas.report import method_axis_table

__all__ = ["RUNS", "StaleFinding", "load", "tables"]

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "docs" / "stability" / "runs.json"


def load(path: Path = RUNS) -> dict[str, Any]:
    """The committed atlas run."""
    return json.loads(path.read_text(encoding="utf-8"))


def tables(data: dict[str, Any]) -> dict[str, str]:
    """The page's blocks by name."""
    axes = [a for a in AXES if a.name in data["axes"]]
    return {"stability-run": run_headline(data),
            "stability-table": "\n".join(method_axis_table(data["rows"], axes)),
            "stability-findings": findings(data, AXES)}
