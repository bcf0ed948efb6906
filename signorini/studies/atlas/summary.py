"""The atlas's summaries: per method, the package's record, and method × axis verdicts."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Any, Iterable, Sequence

from signorini.studies.atlas.axis import Axis, Rows
from signorini.studies.task import BUILD_ONLY


@dataclass
class AtlasResult:
    """Every row of an atlas run, the axes it covered and how long it took."""

    rows: Rows
    axes: tuple[Axis, ...]
    elapsed_s: float
    axis_seconds: dict[str, float]
    quick: bool = False


def method_rows(rows: Iterable[dict[str, Any]]) -> Rows:
    """The runs of methods (not the rows that only build a problem)."""
    return [r for r in rows if r.get("method") != BUILD_ONLY]


def method_summary(rows: Rows) -> list[dict[str, Any]]:
    """Per method: runs, claims of success, how many were correct, and the package's record.

    ``correct_rate`` is the fraction of the method's own claims of success
    that were true (NaN without claims); ``wrapper_rate`` the fraction of its
    runs where the package's status was right.
    """
    out = []
    runs = method_rows(rows)
    for method in dict.fromkeys(r["method"] for r in runs):
        mine = [r for r in runs if r["method"] == method]
        claims = [r for r in mine if r.get("claimed_status") == "converged"]
        correct = sum(bool(r.get("claim_correct")) for r in claims)
        wrapper = sum(bool(r.get("wrapper_right")) for r in mine)
        out.append({"method": method, "runs": len(mine), "claims": len(claims),
                    "claims_correct": correct,
                    "correct_rate": correct / len(claims) if claims else float("nan"),
                    "right": sum(r.get("outcome") == "right" for r in mine),
                    "conservative": sum(bool(r.get("conservative")) for r in mine),
                    "wrapper_right": wrapper, "wrapper_rate": wrapper / len(mine),
                    "statuses": dict(Counter(r["status"] for r in mine))})
    return out


def wrapper_record(rows: Rows) -> tuple[int, int, Rows]:
    """``(right, runs, faults)``: how often the package's status was right, and the rows where not."""
    runs = method_rows(rows)
    faults = [r for r in runs if not r.get("wrapper_right")]
    return len(runs) - len(faults), len(runs), faults


def share(right: int, runs: int) -> str:
    """``right of runs runs (p %)``: how the package's record is stated."""
    return f"{right} of {runs} runs ({100 * right / max(runs, 1):.1f} %)"


def verdicts(rows: Rows, axes: Sequence[Axis]) -> dict[tuple[str, str], str]:
    """``(method, axis) → "works n/n" | "degrades k/n" | "fails 0/n"``: right runs among those that count.

    A run counts unless it only built its problem, was refused for its size,
    or its axis (one of ``axes``) says it does not (:attr:`Axis.counts`).
    """
    by_name = {a.name: a for a in axes}

    def counts(row: dict[str, Any]) -> bool:
        if row.get("status") == "refused" or row.get("method") == BUILD_ONLY:
            return False
        return row["axis"] not in by_name or by_name[row["axis"]].counts(row)

    out = {}
    for r in rows:
        key = (r["method"], r["axis"])
        if key in out or not counts(r):
            continue
        mine = [s for s in rows if (s["method"], s["axis"]) == key and counts(s)]
        right = sum(s.get("outcome") == "right" for s in mine)
        word = "works" if right == len(mine) else ("fails" if right == 0 else "degrades")
        out[key] = f"{word} {right}/{len(mine)}"
    return out


__all__ = ["AtlasResult", "method_rows", "method_summary", "wrapper_record", "share", "verdicts"]
