"""The README's "When methods fail" blocks, written from the committed stability atlas.

    .venv/bin/python tools/readme.py        # after `signorini stability --out docs`

``tables`` renders, from ``docs/stability/runs.json``: the run's headline (runs, time, the
package's record), the method × axis table of ``docs/stability.md`` (the same function draws
both: :func:`signorini.studies.atlas.report.method_axis_table`), and the findings, every number
in them computed here from the rows. A finding also states things the numbers do not show by
themselves ("growth is never seen"); each such statement is checked against the rows, and
``tables`` raises :class:`StaleFinding` when a new run no longer shows it: rewrite the sentence
here, then run tools/readme.py. tests/test_readme_numbers.py holds the README to what this writes.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Callable, Iterable

from signorini.studies.atlas import AXES
from signorini.studies.atlas.report import method_axis_table
from signorini.studies.atlas.summary import method_rows, method_summary, wrapper_record
from signorini.studies.task import DEFAULT_TIME_LIMIT

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "docs" / "stability" / "runs.json"

Rows = list[dict[str, Any]]

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
    """Stop the README's rendering when the atlas no longer shows ``what``."""
    if not holds:
        raise StaleFinding(f"docs/stability/runs.json no longer shows that {what}: rewrite that "
                           "finding in tools/stability.py")


def load(path: Path = RUNS) -> dict[str, Any]:
    """The committed atlas run."""
    return json.loads(path.read_text(encoding="utf-8"))


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


# --- the blocks ----------------------------------------------------------------------------------


def headline(data: dict[str, Any]) -> str:
    rows = data["rows"]
    ok, runs, _ = wrapper_record(rows)
    claim("--time-limit" not in data["command"], "the run used the default time limit")
    info = data["provenance"]
    return (f"**{runs} runs in {data['elapsed_s']:.0f} s** on this {info['cores']}-core machine "
            f"({info['cpu']}, {info['date'][:10]}; at most {DEFAULT_TIME_LIMIT:.0f} s per run); "
            f"the package's status was right in {ok} of them ({100 * ok / runs:.1f} %).")


def table(data: dict[str, Any]) -> str:
    axes = [a for a in AXES if a.name in data["axes"]]
    return "\n".join(method_axis_table(data["rows"], axes))


def step_finding(rows: Rows) -> str:
    cyl, block = (pick(rows, case=c) for c in ("hertz-cylinder", "block"))
    uz_cyl, uz_block = pick(cyl, method="uzawa"), pick(block, method="uzawa")
    diverged = pick(rows, method="uzawa", status="diverged")
    claim(all("cycle" in r["message"] for r in diverged), "Uzawa diverges only in a two-step cycle")
    first_cycle = {case: min(r["value"] for r in pick(diverged, case=case))
                   for case in ("hertz-cylinder", "block")}
    for mine in (uz_cyl, uz_block):  # right from just past the first wrong step up to the cycle
        claim(all(r["outcome"] == "right" for r in mine
                  if r["value"] < first_cycle[mine[0]["case"]] and r["status"] != "max_iter"),
              "Uzawa is right at every step below its cycle that reaches the iteration cap")
    capped = sorted(r["value"] for r in uz_cyl + uz_block if r["status"] == "max_iter")
    claim(capped == [min(r["value"] for r in uz_cyl)] and not pick(uz_block, status="max_iter"),
          "Uzawa stops at its cap only at the cylinder's smallest step")
    cap = one(uz_cyl, value=capped[0])["iterations"]
    bound = uz_cyl[0]["bound_at_solution"]
    claim(first_cycle["hertz-cylinder"] < bound, "the cylinder cycles before its W_AA bound")
    iterations = {v: one(uz_cyl, value=v)["iterations"] for v in (0.1, 0.95)}
    nesterov = pick(rows, method="uzawa-nesterov")
    stalled = {case: [r["value"] for r in pick(nesterov, case=case, status="max_iter")]
               for case in ("hertz-cylinder", "block")}
    grown = pick(nesterov, status="diverged")
    early = [r for r in nesterov if r["value"] <= 0.5]
    uncertified = [r for r in early if r["status"] == "inaccurate"]
    claim(all("cycle" not in r["message"] for r in grown) and min(r["value"] for r in grown) > 1
          and all(r["outcome"] in ("right", "caught", "conservative") for r in early)
          and all(v < 1 for vs in stalled.values() for v in vs),
          "uzawa-nesterov is never wrong to 0.5×, stalls below 1× and grows past it")
    return (f"**Uzawa's step** (axis 1): plain Uzawa is right for ρ up to the bound 2/λ_max(W) on "
            f"a {uz_cyl[0]['dofs']:,}-dof cylinder ({iterations[0.1]:,} iterations at 0.1×, "
            f"{iterations[0.95]:,} at 0.95×) and the {uz_block[0]['dofs']:,}-dof block, except at "
            f"{times(capped[0])} on the cylinder, where it stops at its {cap:,}-iteration cap. "
            "Beyond the bound the package says `diverged` and names a **two-step cycle** (λ "
            "returns every other step; growth is never seen): from "
            f"{times(first_cycle['block'])} on the block, from "
            f"{times(first_cycle['hertz-cylinder'])} on the cylinder, whose active block W_AA "
            f"allows {bound:.2f}×. `uzawa-nesterov` needs ρ ≤ 1/λ_max: up to 0.5× it meets the "
            "KKT residuals, but its stopping rule stops short of the forces: the certificate's "
            f"forward error leaves {len(uncertified)} of its {len(early)} runs there "
            "`inaccurate` (docs/certificate.md); at "
            f"{span(stalled['hertz-cylinder'])} of 2/λ_max ({span(stalled['block'])} on the "
            "block) it stops at `max_iter`, past 1× it diverges by growth.")


def mesh_finding(rows: Rows) -> str:
    levels = sorted({r["value"] for r in rows})

    def series(method: str, key: str) -> list[Any]:
        return [one(rows, method=method, value=v)[key] for v in levels]

    dofs = series("pdas", "dofs")
    pdas, uzawa, nesterov = (series(m, "iterations") for m in ("pdas", "uzawa", "uzawa-nesterov"))
    nested = series("nested", "iterations")
    claim(all(n <= p for n, p in zip(nested, pdas)), "`nested` takes no more steps than PDAS")
    growth = (uzawa[-1] / uzawa[0]) ** (1 / (len(levels) - 1))
    qp = [m for m in methods_of(rows) if m.startswith("qp-") or m == "cvxpy"]
    sparse = [m for m in qp if not pick(rows, method=m, status="refused")]
    every = [m for m in sparse if len(right(pick(rows, method=m))) == len(levels)]
    some = {m: len(right(pick(rows, method=m))) for m in sparse if m not in every}
    partly = [f"{name(m)} at {k}" for m, k in sorted(some.items(), key=lambda i: -i[1]) if k]
    claim(len(every) >= 1, "a sparse QP backend is right at every level")
    at_all = ", ".join(name(m) for m in every)
    return (f"**Mesh** (axis 2, {dofs[0]:,} → {dofs[-1]:,} dofs, h halving): PDAS takes "
            + " → ".join(str(i) for i in pdas) + " steps from a cold start and `nested` "
            + " → ".join(str(i) for i in nested) + " (the zone from Hertz's width for the load, "
            "one factorisation at every level); Uzawa "
            f"{uzawa[0]:,} → {uzawa[-1]:,} iterations (×{growth:.2f} per halving of h), "
            f"`uzawa-nesterov` {nesterov[0]:,} → {nesterov[-1]:,}. Of the sparse QP backends "
            f"{at_all} {'is' if len(every) == 1 else 'are'} right at all {len(levels)} levels at "
            f"tol {power(rows[0]['tol'])}"
            + (" (" + ", ".join(partly) + "; the others at none)." if partly else "."))


def tolerance_finding(rows: Rows) -> str:
    osqp = one(rows, method="qp-osqp", tol=None)
    prox = one(rows, method="qp-proxqp", tol=None)
    claim(osqp["claimed_status"] == prox["claimed_status"] == "converged" and osqp["misclassified"] == 0
          and prox["misclassified"] > 0, "OSQP and ProxQP claim success at their defaults")
    tolerances = sorted({r["tol"] for r in rows if r["tol"] is not None})
    never = [m for m in methods_of(rows) if m != "qp-quadprog"
             and not right(pick(rows, method=m, tol=lambda t: t is not None))]
    daqp_false = [r for r in pick(rows, method="qp-daqp") if r["claimed_status"] == "converged"
                  and not r["claim_correct"]]
    claim(len(daqp_false) == 1, "DAQP makes one false claim")
    return (f"**Tolerance** (axis 3, a {osqp['dofs']:,}-dof cylinder): at its defaults OSQP says "
            f"\"solved\" with λ {pct(osqp['lam_rel'])} off and no node misclassified, ProxQP with "
            f"λ off by {prox['lam_rel']:.1f} times its size, {prox['misclassified']} nodes misclassified "
            f"and Hertz's a and p₀ {pct(prox['a_rel'])} and {pct(prox['p0_rel'])} off (the exact "
            f"answer: {pct(prox['ref_a_rel'], 2)} and {pct(prox['ref_p0_rel'], 2)}); "
            f"{names(never)} are right at no tolerance from {power(tolerances[-1])} to "
            f"{power(tolerances[0])}; DAQP's one false claim is at {power(daqp_false[0]['tol'])} "
            "(below).")


def units_finding(rows: Rows) -> str:
    systems = list(dict.fromkeys(r["value"] for r in rows))
    scaled = pick(rows, case=lambda c: c.endswith(", scaled"))
    raw = pick(rows, case=lambda c: c.endswith(", raw"))
    methods = methods_of(rows)
    for m in methods:
        claim(len({one(scaled, method=m, value=s)["outcome"] for s in systems}) == 1,
              f"{m} behaves the same in every scaled unit system")
    right_scaled = len(right(pick(scaled, value=systems[0])))
    changed = {m: (len(right(pick(scaled, method=m))), len(right(pick(raw, method=m))))
               for m in methods}
    changed = {m: c for m, c in changed.items() if c[0] != c[1]}
    claim(all(s > r for s, r in changed.values()), "raw units never help a method")
    infeasible = [r for r in pick(raw, method="qp-quadprog") if r["status"] == "infeasible"]
    if infeasible:
        claim(all("E=2.1e11" in r["value"] for r in infeasible)
              and len(infeasible) == sum("E=2.1e11" in s for s in systems),
              "quadprog calls exactly the raw problems with E = 2.1e11 infeasible")
    moves = [f"{name(m)} is right in {r} of {len(systems)} (scaled: {s})"
             for m, (s, r) in changed.items() if m != "qp-quadprog" or not infeasible]
    quadprog = (f", and quadprog calls the {len(infeasible)} feasible problems with E = 2.1e11 "
                "`infeasible`" if infeasible else "")
    return (f"**Units** (axis 4): with the default non-dimensionalisation every method behaves the "
            f"same in all {len(systems)} unit systems (E = 1 … 2.1e11, lengths in m or mm; "
            f"{right_scaled} of {len(methods)} methods right in each); in raw units "
            + (", ".join(moves) if moves else "no method changes") + quadprog + ".")


def nodal_finding(nodal: Rows, plain: Rows, order: list[str], dofs: dict[str, int]) -> str:
    """What averaging the volumetric strain at the nodes does on the same meshes (axis 5)."""
    def p0(mesh: str, nu: float, rows: Rows = nodal) -> float:
        return one(rows, case=f"{mesh}, nodal" if rows is nodal else mesh, value=nu)["p0_rel"]

    nus = sorted({r["value"] for r in nodal})[:-1]  # the extreme ν is not certified (below)
    claim(all(p0(m, nu) < 0.01 for m in order for nu in nus),
          "with the nodal average PDAS's p₀ is within 1 % for every ν up to 0.4999 on every mesh")
    claim(all(p0(m, nu) < 0.1 * p0(m, nu, plain) for m in order for nu in (0.499, 0.4999)),
          "with the nodal average p₀ is at least ten times closer than plain P1's at ν ≥ 0.499")
    return ("With the volumetric strain averaged at the nodes (`volumetric=nodal`, the default "
            "from ν = 0.4) nothing locks: p₀'s error at ν = 0.3, 0.49, 0.499, 0.4999 is "
            + "; ".join(", ".join(pct(p0(m, nu), 2) for nu in (0.3, 0.49, 0.499, 0.4999))
                        + f" on {dofs[m]:,} dofs" for m in order) + ".")


def poisson_finding(rows: Rows) -> str:
    every = pick(rows, method="pdas")
    pdas = [r for r in every if not r["case"].endswith(", nodal")]
    nodal = [r for r in every if r["case"].endswith(", nodal")]
    meshes = sorted({r["case"] for r in pdas})
    dofs = {m: pick(pdas, case=m)[0]["dofs"] for m in meshes}
    finest, coarsest = max(meshes, key=dofs.get), min(meshes, key=dofs.get)

    def p0(mesh: str, nu: float) -> float:
        return one(pdas, case=mesh, value=nu)["p0_rel"]

    order = sorted(meshes, key=dofs.get)
    claim(all(p0(m, nu) < 0.01 for m in meshes for nu in (0.3, 0.4, 0.45)),
          "PDAS's p₀ is within 1 % for ν ≤ 0.45 on every mesh")
    claim(all(p0(a, 0.499) > p0(b, 0.499) for a, b in zip(order, order[1:])),
          "refinement lowers the p₀ error at ν = 0.499")
    exact = [m for m in ("pdas", "nested", "condensed") if m in methods_of(rows)]
    extreme = max(r["value"] for r in rows)
    usual = sorted({r["value"] for r in rows} - {extreme})
    claim(all(r["outcome"] == "right" for r in pick(rows, case=coarsest)
              if r["method"] in exact and r["value"] != extreme),
          "the exact methods solve every ν short of the extreme one")
    at_extreme = [r for r in rows if r["value"] == extreme]
    claim(all(r["status"] != "converged" and r["outcome"] != "wrong" for r in at_extreme),
          "no method is converged at the extreme ν, and none is wrong there")
    worst = [r for r in pick(rows, case=coarsest, value=usual[-1])
             if r["method"] in ("uzawa", "petsc-vi") and r["outcome"] != "right"]
    return (f"**ν → 0.5** (axis 5): plain P1 locks, the solvers do not fail: PDAS's p₀ error on the finest "
            f"mesh ({dofs[finest]:,} dofs) is {pct(p0(finest, 0.3))} at ν = 0.3, "
            f"{pct(p0(finest, 0.49))} at 0.49, {pct(p0(finest, 0.499))} at 0.499 and "
            f"{pct(p0(finest, 0.4999), 0)} at 0.4999; at 0.499 each refinement cuts it ("
            + " → ".join(pct(p0(m, 0.499)) for m in order) + "), at 0.4999 it stays large ("
            + " → ".join(pct(p0(m, 0.4999), 0) for m in order) + "). "
            + nodal_finding(nodal, pdas, order, dofs) + " The exact methods solve every ν up to "
            f"{usual[-1]:g}; at {usual[-1]:g} "
            + " and ".join(f"{name(r['method'])} {VERBS.get(r['status'], r['status'])}"
                           for r in worst) + f" on the {dofs[coarsest]:,}-dof mesh. At ν = {extreme!r} "
            "double precision cannot certify the contact forces (the certificate's forward error, "
            f"docs/certificate.md): all {len(at_extreme)} runs there, the exact methods' too, end "
            "`inaccurate` or worse, none `converged`.")


def force_finding(rows: Rows) -> str:
    singular = pick(rows, case="singular K")
    eps = [r for r in rows if r["case"].startswith("regularised")]
    claim(len({r["value"] for r in eps}) == 1, "one regularisation is run with every method")
    fine = right(singular)
    worst = max(r["patch_lam_rel"] for r in fine)
    qp = [m for m in methods_of(singular) if m.startswith("qp-")]
    lost = [m for m in qp if m not in {r["method"] for r in fine}]
    claim({r["method"] for r in fine} == (set(qp) - set(lost)) | {"cvxpy"}
          | {m for m in methods_of(singular) if m.startswith("petsc-")},
          "the QP backends but a few, cvxpy and the PETSc methods are right on the singular K")
    claim({r["method"] for r in singular if r["outcome"] != "right"} - set(lost)
          == {"pdas", "pdas-amg", "auto", "nested", "condensed", "uzawa", "uzawa-nesterov"},
          "PDAS (and pdas-amg, auto's picks), nested, the condensed dual and both Uzawas fail on "
          "the singular K")
    moved = one(eps, method="pdas")["patch_lam_rel"]
    not_helped = [r for r in eps if r["outcome"] != "right"]
    claim(all(r["status"] == "max_iter" for r in not_helped if r["method"].startswith("uzawa")),
          "both Uzawas stop at max_iter on the regularised problem")
    return (f"**Force control** (axis 6): K is singular; {len(fine)} of {len(singular)} methods are "
            "right on it (every QP backend but " + names(lost) + ", cvxpy and the PETSc methods; "
            f"λ within {power(worst)} of the exact patch solution), while PDAS (also `pdas-amg`, and "
            "`auto`, which picks one of them), `nested`, the condensed dual and both Uzawas need K⁻¹ "
            "and fail. The handling: "
            f"`signorini.diagnose.regularise(problem, {power(eps[0]['value'])})` adds "
            f"{power(eps[0]['value'])} · mean(diag K) to the diagonal; then {len(right(eps))} of "
            f"{len(eps)} methods are right and λ moves by {power(moved, 1)} "
            f"({moved / eps[0]['value']:.0f} ε); Uzawa is not helped (both variants stop at "
            "`max_iter`: W gains an eigenvalue of order 1/ε). The scene: "
            "`signorini.scenes.block.force_controlled_problem(pressure=…)`.")


def degenerate_finding(rows: Rows) -> str:
    case = max({r["case"] for r in rows}, key=lambda c: max(r["weak"] for r in pick(rows, case=c)))
    converged = pick(rows, case=case, status="converged")
    claim(all(r["misclassified"] == 0 for r in pick(rows, status="converged")),
          "no converged method shows a misclassified node")
    strict = [r for r in converged if r["misclassified_strict"] > 0]
    claim(max((r["misclassified_strict"] for r in strict), default=0) <= 1,
          "a strict count flags at most one node")
    flagged = (f"a comparison without the weak label would flag one for {len(strict)} of the "
               f"{len(converged)} converged methods" if strict else
               f"even a comparison without the weak label flags none of the {len(converged)} "
               "converged methods")
    return ("**Degenerate contact** (axis 7, `signorini solve block --set "
            f"{case}`): nodes that touch with zero force are labelled weakly "
            f"active and left out; no converged method shows a misclassified node, and {flagged}.")


def ill_posed_finding(rows: Rows) -> str:
    penetrated = [r for r in pick(rows, case="penetrated") if r["method"] != "(build)"]
    statuses = {s: len(pick(penetrated, status=s)) for s in ("infeasible", "failed")}
    claim(sum(statuses.values()) == len(penetrated), "every method says infeasible or failed")
    unclear = "float division by zero"
    claim(any(unclear in str(r["message"]) for r in penetrated), f"a message says '{unclear}'")
    return ("**Ill-posed input** (axis 8): an empty contact set and a zero-weight candidate are "
            "refused when the problem is built; `signorini.diagnose.diagnose(problem)` names an "
            "obstacle the Dirichlet data already penetrate (infeasible), a candidate listed twice "
            "(λ not unique) and a singular K. On the penetrated obstacle "
            f"{statuses['infeasible']} methods say `infeasible` and {statuses['failed']} "
            f"`failed`, some with unclear messages (\"{unclear}\").")


def rates_text(summary: list[dict[str, Any]]) -> str:
    """Methods grouped by the share of their claims that were correct, best first."""
    groups: dict[int, list[str]] = {}
    for s in summary:
        if math.isfinite(s["correct_rate"]):
            groups.setdefault(round(100 * s["correct_rate"]), []).append(s["method"])
    ordered = sorted(groups.items(), reverse=True)
    low = [(rate, ms) for rate, ms in ordered if 0 < rate < 20]
    parts = [f"{rate} % {'of the time ' if i == 0 else ''}for {names(ms)}" for i, (rate, ms) in enumerate(ordered) if rate >= 20]
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
    return (f"**The package's status was right in {ok} of {runs} runs ({100 * ok / runs:.1f} %)"
            + (", not 100 %.** " if faults else ".** ")
            + f"The {len(faults)} exceptions, each with a line that repeats it in the report: in "
            f"raw units with E = 2.1e11 quadprog's silent failure is reported as `infeasible` "
            f"({len(quadprog)}); DAQP at `--tol {power(d['tol'])}` is `converged` with λ "
            f"{pct(d['lam_rel'], 0)} off, {d['weak_penetrating']} nodes carrying no force while "
            f"penetrating (its primal residual {power(d['kkt_worst'], 1)} is within the tolerance asked "
            f"for) (1). No method's false claim of success got through at a tolerance below "
            f"{power(loosest)}. Methods' own claims were right " + rates_text(method_summary(rows))
            + ".")


FINDINGS: dict[str, Callable[[Rows], str]] = {
    "uzawa-step": step_finding, "mesh": mesh_finding, "tolerance": tolerance_finding,
    "units": units_finding, "poisson": poisson_finding, "force-control": force_finding,
    "degenerate": degenerate_finding, "ill-posed": ill_posed_finding}


def findings(data: dict[str, Any]) -> str:
    rows = data["rows"]
    lines = [f"- {FINDINGS[axis]([r for r in rows if r['axis'] == axis])}"
             for axis in data["axes"] if axis in FINDINGS]
    return "\n".join(lines) + "\n\n" + status_finding(data)


def tables(data: dict[str, Any]) -> dict[str, str]:
    """The README's blocks by name."""
    return {"stability-run": headline(data), "stability-table": table(data),
            "stability-findings": findings(data)}
