"""Write the generated blocks of the docs pages (results, performance, accuracy, estimate, peer,
convergence, derivatives, mesher, certificate) from the committed artefacts they quote; the README itself carries none.

    .venv/bin/python tools/readme.py          # after `signorini validate --out docs/validation`,
                                              # `signorini stability --out docs`, ...

Each block sits between ``<!-- generated: NAME -->`` and ``<!-- end generated -->``;
``tests/test_readme_numbers.py`` fails when a block differs from what this writes.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import accuracy  # noqa: E402  (tools/accuracy.py: the accuracy study's tables)
import amg_bench  # noqa: E402  (tools/amg_bench.py: 3D at scale, docs/amg)
import budget  # noqa: E402  (tools/budget.py: the 10⁶-dof command against one factorisation)
import certificate_pinning  # noqa: E402  (tools/certificate_pinning.py: a certificate with no factorisation)
import derivatives as derivative_cost  # noqa: E402  (tools/derivatives.py: a derivative against the solve)
import estimate as estimate_study  # noqa: E402  (tools/estimate.py: the estimate's effectivity)
import finite_sphere  # noqa: E402  (tools/finite_sphere.py: the finite sphere against Hertz)
import mesher_compare  # noqa: E402  (tools/mesher_compare.py: the Hertz discs' three meshers)
import mesher_front  # noqa: E402  (tools/mesher_front.py: accuracy against time per mesher)
import slider_timing  # noqa: E402  (tools/slider_timing.py: a small solve by stage, the sliders)
import snapshot  # noqa: E402  (tools/snapshot.py: the same answers and the time across one door)
import stability  # noqa: E402  (tools/stability.py: the stability atlas's blocks)
import startup  # noqa: E402  (tools/startup.py: whole-process time before the contact)
import two_bodies  # noqa: E402  (tools/two_bodies.py: the patch test and Hertz between two bodies)

from signorini.files import atomic_write_text  # noqa: E402
from signorini.output.report import readme_validation  # noqa: E402
from signorini.studies.peer_report import matching_table, peer_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "docs" / "results.md"          # validation, accuracy on demand, GetFEM, the atlas
PERFORMANCE = ROOT / "docs" / "performance.md"  # 3D at scale, the 1M-dof cylinder, nested's ratios
ACCURACY = ROOT / "docs" / "accuracy.md"
ESTIMATE = ROOT / "docs" / "estimate.md"
PEER = ROOT / "docs" / "peer.md"
CONVERGENCE = ROOT / "docs" / "convergence.md"
DERIVATIVES = ROOT / "docs" / "derivatives.md"
MESHER = ROOT / "docs" / "mesher.md"
TWO_BODIES = ROOT / "docs" / "two-bodies.md"
ONE_DOOR = ROOT / "docs" / "one-door.md"
CERTIFICATE = ROOT / "docs" / "certificate.md"
DOCUMENTS = (RESULTS, PERFORMANCE, ACCURACY, ESTIMATE, PEER, CONVERGENCE, DERIVATIVES, MESHER,
             TWO_BODIES, ONE_DOOR, CERTIFICATE)
#: the contact half-width of each convergence study's scene at its defaults (h / a in the tables)
STUDY_A = {"hertz-cylinder": 0.05, "hertz-sphere": 0.05, "reverse-hertz": 0.02, "punch": 1.0}
STUDY_COLUMNS = {"p0_rel": "p₀ error", "a_rel": "a error", "pressure_l2_rel": "pressure L2 error",
                 "pressure_max_rel": "pressure max error, \\|x\\| ≤ a/2",
                 "edge_over_centre": "edge node pressure / (P/πa)",
                 "estimate": "estimate η / ‖u_h‖", "pressure_estimate": "pressure estimate"}


def grading_table(path: Path) -> str:
    """The graded study against the uniform one (``converge --uniform-levels``), level by level,
    and the dofs each needs for the p₀ target, from the committed JSON."""
    record = json.loads(path.read_text())
    series = {name: [r for r in record[key]["rows"] if r["status"] == "converged"]
              for name, key in (("graded", "study"), ("uniform", "uniform"))}
    lines = ["| mesh | level | dofs | p₀ error | a error | pressure L2 error | estimate η / ‖u_h‖ |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, rows in series.items():
        lines += [f"| {name} | {r['level']} | {r['dofs']:,} | {100 * r['errors']['p0_rel']:.3g} % "
                  f"| {100 * r['errors']['a_rel']:.3g} % | {100 * r['errors']['pressure_l2_rel']:.3g} % "
                  f"| {100 * r['errors']['estimate']:.3g} % |" for r in rows]
    g = record["grading"]
    lines += ["", f"For a p₀ error of {100 * g['target']:g} %: graded {g['graded_dofs']:,.0f} dofs "
              f"({g['graded_how']}), uniform {g['uniform_dofs']:,.0f} ({g['uniform_how']}): "
              f"grading saves {g['saving']:,.0f}× the dofs."]
    return "\n".join(lines)


def convergence_table(path: Path, method: str = "pdas") -> str:
    """One committed convergence study (its JSON) as docs/convergence.md shows it: a row per
    level of ``method``, the errors and both estimates, and every fitted rate."""
    study = json.loads(path.read_text())["study"]
    metrics, a = study["metrics"], STUDY_A[study["scene"]]
    rows = [r for r in study["rows"] if r["method"] == method and r["status"] == "converged"]
    lines = ["| level | dofs | h / a | " + " | ".join(STUDY_COLUMNS[m] for m in metrics) + " |",
             "|---:|---:|---:|" + "---:|" * len(metrics)]
    for r in rows:
        cells = [f"{r['errors'][m]:.3g}" if m == "edge_over_centre" else f"{100 * r['errors'][m]:.3g} %"
                 for m in metrics]
        lines.append(f"| {r['level']} | {r['dofs']:,} | 1/{a / r['h']:.0f} | " + " | ".join(cells) + " |")
    rates = study["rates"][method]
    lines += ["", f"Fitted rates in h ({method}; `condensed` gives the same to 1e-6): "
              + ", ".join(f"{STUDY_COLUMNS[m]} {rates[m]:.2f}" for m in metrics) + "."]
    return "\n".join(lines)


def one_million(run: Path) -> str:
    """The performance page's headline from the committed 1M-dof run (its JSON and /usr/bin/time -v)."""
    record = json.loads((run / "result.json").read_text())
    timing = dict(line.strip().rsplit(": ", 1) for line in (run / "time.txt").read_text().splitlines()
                  if ": " in line)
    minutes, seconds = timing["Elapsed (wall clock) time (h:mm:ss or m:ss)"].split(":")[-2:]
    wall = 60 * float(minutes) + float(seconds)
    peak = float(timing["Maximum resident set size (kbytes)"]) / 1024 ** 2
    worst = max(record["kkt"].values())
    hertz = record["hertz"]
    return (f"**A {record['dofs']:,}-dof Hertz cylinder, solved exactly end to end in {wall:.1f} s "
            f"and {peak:.1f} GB** (one run, `docs/speed/one-million/`: every KKT residual ≤ "
            f"{worst:.1e}; Hertz's p₀ within {100 * hertz['p0_rel']:.2f} %, a within "
            f"{100 * hertz['a_rel']:.2f} %; assembly {record['time']['assemble_s']:.1f} s of it, "
            f"the solve {record['time']['solve_s']:.2f} s)")


def nested_ratios(csv_path: Path) -> str:
    """The performance page's line on nested against one factorisation, from the committed bench CSV."""
    import csv

    rows = list(csv.DictReader(csv_path.open()))
    parts = [f"{int(r['dofs']):,} dofs: {float(r['time_s']):.2f} s against {float(r['factor_s']):.2f} s, "
             f"**{float(r['ratio_to_factor']):.2f}×**" for r in rows if r["method"] == "nested"]
    return ("`nested` against one PARDISO factorisation + solve of the same K, in one run "
            "([`docs/bench-nested/bench.md`](bench-nested/bench.md)): " + "; ".join(parts) + ".")


def blocks(document: Path = RESULTS) -> dict[str, str]:
    """The generated blocks of ``document`` by name, from their artefacts."""
    if document == RESULTS:
        report = json.loads((ROOT / "docs" / "validation" / "report.json").read_text())
        peer = peer_table(json.loads((ROOT / "docs" / "peer" / "peer.json").read_text())["rows"])
        return {"validation": readme_validation(report),
                "peer": "\n".join(peer[peer.index("") + 1:]),  # the summary of docs/peer/peer.md
                "adaptive-summary": estimate_study.adaptive_summary(estimate_study.load("adaptive")),
                **stability.tables(stability.load())}
    if document == PERFORMANCE:
        return {"one-million": one_million(ROOT / "docs" / "speed" / "one-million"),
                "nested-ratios": nested_ratios(ROOT / "docs" / "bench-nested" / "bench.csv"),
                "amg": amg_bench.readme_paragraph(amg_bench.read()),
                "amg-scale": amg_bench.scale_table(amg_bench.read()),
                "amg-nested-again": amg_bench.nested_again(amg_bench.read()),
                "budget": budget.table(budget.load()),
                "slider-stages": slider_timing.table(slider_timing.load()),
                "slider-steps": slider_timing.steps(slider_timing.load())}
    if document == ACCURACY:
        runs = {}
        for name in ("peer-nu0", "peer-nu045"):  # every run of docs/peer-nu0, docs/peer-nu045
            peer = peer_table(json.loads((ROOT / "docs" / name / "peer.json").read_text())["rows"])
            runs[name] = "\n".join(peer[:peer.index("")])
        runs["peer-nu045-summary"] = "\n".join(peer[peer.index("") + 1:])
        return {**accuracy.tables(accuracy.load()), **finite_sphere.tables(finite_sphere.load()), **runs}
    if document == PEER:
        peer = peer_table(json.loads((ROOT / "docs" / "peer" / "peer.json").read_text())["rows"])
        two = peer_table(json.loads((ROOT / "docs" / "peer-two" / "peer.json").read_text())["rows"])
        return {"peer-runs": "\n".join(peer[:peer.index("")]),
                "peer-two-runs": "\n".join(two[:two.index("")]),  # hertz-two-cylinders
                "peer-two-summary": "\n".join(two[two.index("") + 1:]),
                "peer-two-matching": "\n".join(matching_table(json.loads(
                    (ROOT / "docs" / "peer-two" / "master-ratio.json").read_text())["rows"])),
                "peer-summary": "\n".join(peer[peer.index("") + 1:]),
                "startup": startup.table(startup.load()), "startup-reading": startup.reading(startup.load())}
    if document == CONVERGENCE:
        return {**{f"convergence-{scene}": convergence_table(
            ROOT / "docs" / "convergence" / f"convergence-{scene}.json") for scene in STUDY_A},
                "grading": grading_table(ROOT / "docs" / "convergence" / "grading"
                                         / "convergence-hertz-cylinder.json")}
    if document == ESTIMATE:
        return estimate_study.tables(estimate_study.load(), estimate_study.load("adaptive"),
                                    estimate_study.load("punch"), estimate_study.load("start"))
    if document == DERIVATIVES:
        return {"derivative-cost": derivative_cost.cost_table(derivative_cost.load())}
    if document == MESHER:
        first, rows = mesher_compare.load(mesher_compare.FIRST), mesher_compare.load()
        return {"mesher-first": mesher_compare.table(first),
                "mesher-first-summary": mesher_compare.summary(first),
                "mesher-runs": mesher_compare.table(rows), "mesher-summary": mesher_compare.summary(rows),
                "mesher-load": mesher_compare.machine_load(),
                "mesher-front": mesher_front.table(mesher_front.load()),
                "mesher-front-load": mesher_front.machine_load()}
    if document == TWO_BODIES:
        return {**{f"two-bodies-{name}": table for name, table in two_bodies.tables(two_bodies.load()).items()},
                "two-bodies-cost": two_bodies.cost_table(json.loads(two_bodies.COST.read_text()))}
    if document == ONE_DOOR:
        runs = ROOT / "docs" / "one-door"
        return {"one-door-compare": snapshot.compare_table(runs / "old.npz", runs / "new.npz"),
                "one-door-speed": snapshot.speed_table(json.loads((runs / "speed.json").read_text()))}
    if document == CERTIFICATE:
        return {"certificate-pinning": certificate_pinning.table(certificate_pinning.load())}
    raise ValueError(f"no generated blocks for {document}")


def pattern(name: str) -> re.Pattern:
    # the body may be empty (a block not yet written): the newline before the end marker is optional
    return re.compile(rf"(<!-- generated: {name} -->\n)(.*?)(\n?<!-- end generated -->)", re.S)


def fill_blocks(document: Path, bodies: dict[str, str], required: bool = True) -> None:
    """Write each generated block of ``document`` from ``bodies``; a block the document lacks
    stops the tool when ``required`` (the study's own page), else is left out (a page that
    quotes only some of them)."""
    text = document.read_text(encoding="utf-8")
    for name, body in bodies.items():
        if not pattern(name).search(text):
            if required:
                raise SystemExit(f"{document.name} has no block '{name}'")
            continue
        text = pattern(name).sub(lambda m, body=body: m.group(1) + body + m.group(3), text)
    atomic_write_text(document, text)


def head_commit() -> str:
    """HEAD's short hash (or $SIGNORINI_COMMIT when run from an export of a commit)."""
    import os
    import subprocess

    if os.environ.get("SIGNORINI_COMMIT"):
        return os.environ["SIGNORINI_COMMIT"]
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def provenance(script: str) -> dict:
    """Where a study tool's run was made: its command, HEAD's hash, the machine, the load."""
    import os
    import platform

    return {"command": f"python tools/{script}", "commit": head_commit(),
            "machine": f"{platform.node()}: {platform.processor() or platform.machine()}, "
                       f"{os.cpu_count()} cores, Python {platform.python_version()}",
            "load_before": list(os.getloadavg())}


def study_main(doc: str, out: Path, run, write_doc) -> int:
    """The command line of a study tool: ``--doc`` renders ``doc``'s tables from the committed
    ``out``; without it the study runs and ``out`` is written (atomically)."""
    import argparse

    from signorini.files import to_json

    parser = argparse.ArgumentParser(description=sys.modules["__main__"].__doc__.split("\n")[0])
    parser.add_argument("--doc", action="store_true", help=f"write {doc}'s tables")
    if parser.parse_args().doc:
        write_doc(json.loads(out.read_text()))
        return 0
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, to_json(run()))
    print(f"written: {out}", file=sys.stderr)
    return 0


def current(text: str, name: str) -> str | None:
    match = pattern(name).search(text)
    return match.group(2) if match else None


def main() -> int:
    for document in DOCUMENTS:
        text = document.read_text(encoding="utf-8")
        for name, body in blocks(document).items():
            if current(text, name) is None:
                print(f"{document.name} has no block '{name}'", file=sys.stderr)
                return 1
            text = pattern(name).sub(lambda m, body=body: m.group(1) + body + "\n<!-- end generated -->", text)
        atomic_write_text(document, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
