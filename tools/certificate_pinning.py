"""What a certificate costs when the answer's method held no factorisation (docs/certificate.md).

    .venv/bin/python tools/certificate_pinning.py     # writes docs/speed/certificate-pinning.json

On three Hertz cylinders (the default, ``refine=1``, and 261,984 dofs graded to the contact), the
exact answer is certified as an answer given as arrays (no factorisation of its own, as a QP
backend's or ``signorini.certificate(problem, u=, force=)``'s): once with the active dofs pinned
in one factorisation of K (the certificate's way from ``PINNED_FROM`` active rows) and once by
bordering a plain factorisation (a back-solve a row). Beside them: how many back-solves one
factorisation of K costs, the ratio ``PINNED_FROM`` rests on. Fastest of ``REPEAT`` each, in one
process; tools/readme.py renders docs/certificate.md's table (:func:`table`) from the committed file.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "speed" / "certificate-pinning.json"
REPEAT = 3
SIZES = ({}, {"refine": 1}, {"refine": 2, "n_contact": 110, "grading": 0.1})


def fastest(step, repeat: int = REPEAT) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        step()
        best = min(best, time.perf_counter() - start)
    return best


def measure(params: dict) -> dict:
    import signorini
    from signorini.certification import kkt
    from signorini.numerics.factor import counting, factorize
    from signorini.problem.contact import ContactSolution

    result = signorini.solve("hertz-cylinder", params=params)
    problem, exact = result.problem, result.solution

    def certify(pinned_from: int):
        kkt.PINNED_FROM = pinned_from
        given = ContactSolution("given", exact.u, exact.lam, "converged")
        problem._factor = None  # no factorisation cached from an earlier certificate
        with counting() as work:
            cert = kkt.certificate(problem, given)
        return cert, work

    kept = kkt.PINNED_FROM
    try:
        rows = {}
        for way, pinned_from in (("pinned", 0), ("bordered", problem.m + 1)):
            cert, work = certify(pinned_from)
            rows[way] = {"seconds": fastest(lambda: certify(pinned_from)),
                         "factorisations": work.factorisations, "back_solves": work.back_solves,
                         "force_error": cert.force_error}
    finally:
        kkt.PINNED_FROM = kept
    factor_s = fastest(lambda: factorize(problem.K))
    factor = factorize(problem.K)
    rhs = np.ones(problem.n)
    solve_s = fastest(lambda: factor.solve(rhs), 10)
    return {"params": params, "dofs": problem.n, "active": int((exact.lam > 0).sum()),
            "factor_s": factor_s, "back_solve_s": solve_s, **rows}


def table(data: dict) -> str:
    lines = ["| dofs | active rows | one factorisation, in back-solves | pinned: factorisations, back-solves, s "
             "| bordered: factorisations, back-solves, s | bordered / pinned |",
             "|---:|---:|---:|---|---|---:|"]
    for row in data["rows"]:
        pinned, bordered = row["pinned"], row["bordered"]
        lines.append(f"| {row['dofs']:,} | {row['active']} | {row['factor_s'] / row['back_solve_s']:.0f} "
                     f"| {pinned['factorisations']}, {pinned['back_solves']}, {pinned['seconds']:.3f} "
                     f"| {bordered['factorisations']}, {bordered['back_solves']}, {bordered['seconds']:.3f} "
                     f"| {bordered['seconds'] / pinned['seconds']:.1f}× |")
    lines.append("")
    lines.append(f"Measured {data['date']} on {data['machine']} by `{data['command']}` (fastest of "
                 f"{REPEAT}, load average {data['load_before'][0]:.1f} before the run); the run is "
                 "`docs/speed/certificate-pinning.json`.")
    return "\n".join(lines)


def load() -> dict:
    return json.loads(OUT.read_text())


def main() -> int:
    from datetime import datetime, timezone

    from readme import provenance
    from signorini.files import atomic_write_text, to_json

    data = {**provenance("certificate_pinning.py"), "date": datetime.now(timezone.utc).date().isoformat(),
            "rows": [measure(params) for params in SIZES]}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(OUT, to_json(data))
    print(f"written: {OUT}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
