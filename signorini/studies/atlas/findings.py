"""The atlas's findings in a paragraph per axis, each number computed from the rows.

:func:`findings` and :func:`run_headline` write the "When methods fail" blocks of docs/results.md
(tools/stability.py renders them from ``docs/stability/runs.json``); each axis module states its
own paragraph (:attr:`Axis.headline`) with the helpers here. A paragraph also states things the
numbers do not show by themselves ("growth is never seen"); each such statement is checked
against the rows with :func:`claim`, which raises :class:`StaleFinding` when a new run no longer
shows it: rewrite that sentence in its axis module, then run tools/readme.py.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Iterable, Sequence

from signorini.studies.atlas.axis import Axis, Rows
from signorini.studies.atlas.summary import method_rows, method_summary, share, wrapper_record
from signorini.studies.task import DEFAULT_TIME_LIMIT

#: how the findings name the methods
NAMES = {"pdas": "PDAS", "nested": "`nested`", "condensed": "the condensed dual",
         "uzawa": "Uzawa", "uzawa-nesterov": "`uzawa-nesterov`", "qp-clarabel": "Clarabel",
         "qp-cvxopt": "CVXOPT", "qp-daqp": "DAQP", "qp-ecos": "ECOS", "qp-highs": "HiGHS",
         "qp-osqp": "OSQP", "qp-piqp": "PIQP", "qp-proxqp": "ProxQP", "qp-qpalm": "QPALM",
         "qp-quadprog": "quadprog", "qp-scs": "SCS", "cvxpy": "cvxpy", "petsc-vi": "`petsc-vi`",
         "petsc-tron": "`petsc-tron`", "petsc-gpcg": "`petsc-gpcg`"}


#: what a status does, in a sentence
VERBS = {"max_iter": "stops at `max_iter`", "failed": "fails", "diverged": "diverges",
         "inaccurate": "is inaccurate"}



class StaleFinding(RuntimeError):
    """A sentence of the findings says something the committed atlas no longer shows."""


def claim(holds: bool, what: str) -> None:
    """Stop the rendering of docs/results.md when the atlas no longer shows ``what``."""
    if not holds:
        raise StaleFinding(f"docs/stability/runs.json no longer shows that {what}: rewrite that "
                           "finding in its axis module (signorini/studies/atlas/)")



# --- helpers -------------------------------------------------------------------------------------


def name(method: str) -> str:
    return NAMES.get(method, f"`{method}`")


def names(methods: Iterable[str]) -> str:
    """``A, B and C``."""
    shown = [name(m) for m in methods]
    return shown[0] if len(shown) == 1 else ", ".join(shown[:-1]) + " and " + shown[-1]


def pick(rows: Rows, **match: Any) -> Rows:
    """The rows whose fields equal ``match`` (a callable value is a test of the field)."""
    def fits(row: dict[str, Any]) -> bool:
        return all(want(row.get(k)) if callable(want) else row.get(k) == want
                   for k, want in match.items())
    return [r for r in rows if fits(r)]


def one(rows: Rows, **match: Any) -> dict[str, Any]:
    found = pick(rows, **match)
    claim(len(found) == 1, f"exactly one run has {match}")
    return found[0]


def pct(x: float, digits: int = 1) -> str:
    return f"{100 * x:.{digits}f} %"


def power(x: float, digits: int = 0) -> str:
    """``1e-8``, ``1.1e-6`` (not ``1e-08``)."""
    mantissa, exponent = f"{x:.{digits}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def times(x: float) -> str:
    return f"{x:g}×"


def span(values: list[float], text: Callable[[float], str] = times) -> str:
    """``0.9–0.99×`` (or one value)."""
    low, high = min(values), max(values)
    return text(low) if low == high else f"{text(low)[:-1]}–{text(high)}"


def right(rows: Rows) -> Rows:
    return [r for r in rows if r.get("outcome") == "right"]


def methods_of(rows: Rows) -> list[str]:
    return list(dict.fromkeys(r["method"] for r in rows))



# --- the run as a whole ------------------------------------------------------------------------


def run_headline(data: dict[str, Any]) -> str:
    """The run's size and time, the machine, and the package's record."""
    rows = data["rows"]
    ok, runs, _ = wrapper_record(rows)
    claim("--time-limit" not in data["command"], "the run used the default time limit")
    info = data["provenance"]
    return (f"**{runs} runs in {data['elapsed_s']:.0f} s** on this {info['cores']}-core machine "
            f"({info['cpu']}, {info['date'][:10]}; at most {DEFAULT_TIME_LIMIT:.0f} s per run); "
            f"the package's status was right in {ok} of them ({100 * ok / runs:.1f} %).")


def rates_text(summary: list[dict[str, Any]]) -> str:
    """Methods grouped by the share of their claims that were correct, best first."""
    groups: dict[int, list[str]] = {}
    for s in summary:
        if math.isfinite(s["correct_rate"]):
            groups.setdefault(round(100 * s["correct_rate"]), []).append(s["method"])
    ordered = sorted(groups.items(), reverse=True)
    low = [(rate, ms) for rate, ms in ordered if 0 < rate < 20]
    parts = [f"{rate} % {'of the time ' if i == 0 else ''}for {names(ms)}"
             for i, (rate, ms) in enumerate(ordered) if rate >= 20]
    if low:
        parts.append(f"{min(r for r, _ in low)}–{max(r for r, _ in low)} % for "
                     + names(m for _, ms in low for m in ms))
    zero = groups.get(0, [])
    return ", ".join(parts) + (f" (0 % for {names(zero)})" if zero else "")


def status_finding(data: dict[str, Any]) -> str:
    rows = data["rows"]
    ok, runs, faults = wrapper_record(rows)
    false_claims = [r for r in method_rows(rows) if r.get("claimed_status") == "converged"
                    and not r.get("claim_correct") and r["status"] == "converged"]
    if not faults:
        claim(not false_claims, "no false claim got through")
        return (f"**The package's status was right in all {runs} runs (100 %).** No method's false "
                "claim of success got through. Methods' own claims were right "
                + rates_text(method_summary(rows)) + ".")
    quadprog = [r for r in faults if r["method"] == "qp-quadprog"]
    daqp = [r for r in faults if r["method"] == "qp-daqp"]
    claim(len(quadprog) + len(daqp) == len(faults), "the faults are quadprog's and DAQP's")
    claim(all(r["status"] == "infeasible" and "raw" in r["case"] and "E=2.1e11" in r["case"]
              for r in quadprog), "quadprog's faults are `infeasible` in raw units with E = 2.1e11")
    claim(len(daqp) == 1, "DAQP has one fault")
    d = daqp[0]
    claim(d["status"] == "converged" and d["misclassified"] == 0 and d["weak_penetrating"] > 0,
          "DAQP's fault is a converged answer with nodes penetrating at zero force")
    loosest = min(r["tol"] for r in false_claims)
    claim(all(r["tol"] == loosest for r in false_claims), "false claims got through only at one tolerance")
    return (f"**The package's status was right in {share(ok, runs)}, not 100 %.** "
            f"The {len(faults)} exceptions, each with a line that repeats it in the report: in "
            f"raw units with E = 2.1e11 quadprog's silent failure is reported as `infeasible` "
            f"({len(quadprog)}); DAQP at `--tol {power(d['tol'])}` is `converged` with λ "
            f"{pct(d['lam_rel'], 0)} off, {d['weak_penetrating']} nodes carrying no force while "
            f"penetrating (its primal residual {power(d['kkt_worst'], 1)} is within the tolerance asked "
            f"for) (1). No method's false claim of success got through at a tolerance below "
            f"{power(loosest)}. Methods' own claims were right " + rates_text(method_summary(rows))
            + ".")


def findings(data: dict[str, Any], axes: Sequence[Axis]) -> str:
    """Each axis's paragraph (of ``axes`` run in ``data``), then the package's record."""
    by_name = {a.name: a for a in axes if a.headline is not None}
    lines = [f"- {by_name[axis].headline(by_name[axis].rows(data['rows']))}"
             for axis in data["axes"] if axis in by_name]
    return "\n".join(lines) + "\n\n" + status_finding(data)


__all__ = ["StaleFinding", "claim", "name", "names", "pick", "one", "pct", "power", "times",
           "span", "right", "methods_of", "run_headline", "rates_text", "status_finding",
           "findings", "VERBS"]
