"""Benchmarks: scenes × sizes × methods × tolerance levels → one tidy CSV row per run.

Each run happens in its own process with a time limit, so that a backend that
hangs or crashes costs one failed row and nothing else. Problems are
assembled once per size and cached as ``.npz`` beside the CSV; every row
carries the time of one factorisation + solve of the same K with the same
backend, measured in the same process, so that methods are compared as
ratios measured in one run. Rows are appended one ``write`` at a time and the
run resumes where it stopped: an interrupted benchmark leaves a valid CSV.

Metrics follow qpbenchmark: a run is a *success* when the method says
``converged`` (which the package grants only when the KKT certificate is
within the tolerance); its claim is *correct* when the method's own status
and the certificate agree; times, normalised by the fastest success on the
same problem, are summarised by their shifted geometric mean (shift 10).
"""

from __future__ import annotations

import csv
import io
import json
import logging
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np
import scipy.sparse as sp

from signorini.errors import InputError
from signorini.problem import ContactProblem
from signorini.solvers import cluster

log = logging.getLogger(__name__)

#: the exact method whose answer every run is compared with: the fastest exact one (its KKT
#: certificate is checked like every other; tests hold it to pdas at 1e-8 on small scenes)
REFERENCE = "nested"
#: named tolerance levels (qpbenchmark's); "default" leaves each backend's own settings
TOLERANCES = {"low": 1e-3, "mid": 1e-6, "high": 1e-9, "default": None}
COLUMNS = ("scene", "size", "dofs", "candidates", "method", "ranks", "tolerance", "status",
           "claimed_status",
           "iterations", "build_s", "solve_s", "time_s", "factor_s", "ratio_to_factor",
           "kkt_worst", "lam_rel", "misclassified", "p0_rel", "a_rel", "message")


@dataclass(frozen=True)
class Run:
    scene: str
    size: str
    params: dict[str, Any]
    method: str
    tolerance: str
    #: MPI ranks (petsc methods only; the others run in one process)
    ranks: int = 1

    @property
    def label(self) -> str:
        """The method as the report names it: ``petsc-vi n=2`` for 2 ranks."""
        return self.method if self.ranks == 1 else f"{self.method} n={self.ranks}"

    @property
    def key(self) -> tuple[str, str, str, str]:
        return (self.scene, self.size, self.label, self.tolerance)


# --- one run, in a worker process -------------------------------------------------------------

def run_in_worker(problem_path: Path, method: str, tolerance: str) -> dict[str, Any]:
    """Time one factorisation + solve of K, then one method, and measure its answer."""
    from signorini.kkt import certificate, compare
    from signorini.numerics.factor import factorize, resolve_backend
    from signorini.references import reference_metrics
    from signorini.solvers.registry import solve

    problem = ContactProblem.load(problem_path)
    backend = resolve_backend(None, problem.n)
    factorize(sp.identity(2, format="csc"), backend).solve(np.ones(2))  # load the library first
    start = time.perf_counter()
    factorize(problem.K, backend).solve(problem.f)
    factor_s = time.perf_counter() - start
    solution = solve(problem, method, tol=TOLERANCES[tolerance])
    elapsed = solution.extras["method_s"]  # the method alone, not the certificate that judges it
    reference = _reference(problem, problem_path, solution if method == REFERENCE else None)
    cert = certificate(problem, solution)
    vs = compare(problem, reference, solution)
    metrics = reference_metrics(problem, solution)
    return {"status": solution.status,
            "claimed_status": solution.own_status,
            "iterations": solution.iterations, "build_s": solution.build_time,
            "solve_s": solution.solve_time, "time_s": elapsed, "factor_s": factor_s,
            "ratio_to_factor": elapsed / factor_s, "kkt_worst": cert.worst()[1],
            "lam_rel": vs.lam_rel, "misclassified": vs.misclassified,
            "p0_rel": metrics.get("p0_rel", np.nan), "a_rel": metrics.get("a_rel", np.nan),
            "message": solution.message}


def _reference(problem: ContactProblem, problem_path: Path, exact=None):
    """The exact answer of the problem (by :data:`REFERENCE`), computed once and kept beside it."""
    from signorini.problem import ContactSolution
    from signorini.solvers.registry import solve

    path = problem_path.with_suffix(".reference.npz")
    if path.exists():
        z = np.load(path)
        return ContactSolution(REFERENCE, z["u"], z["lam"], "converged")
    exact = exact if exact is not None else solve(problem, REFERENCE, tol=1e-9)
    if exact.status == "converged":
        buffer = io.BytesIO()
        np.savez(buffer, u=exact.u, lam=exact.lam)
        from signorini.files import atomic_write_bytes
        atomic_write_bytes(path, buffer.getvalue())
    return exact


def _worker_main() -> None:
    from signorini.solvers import cluster

    args = json.loads(sys.argv[1])
    logging.disable(logging.WARNING)
    if cluster.launched_size() > 1 and cluster.rank() != 0:
        cluster.serve()  # rank 0 runs the benchmark; this rank takes part in its solves
        return
    try:
        row = run_in_worker(Path(args["problem"]), args["method"], args["tolerance"])
    except Exception as exc:  # every exception becomes a failed row, never a dead benchmark
        row = {"status": "failed", "message": f"{type(exc).__name__}: {exc}"}
    finally:
        cluster.release()
    print(json.dumps(row, default=float))


# --- the runner ------------------------------------------------------------------------------

def done_keys(path: Path) -> set[tuple[str, str, str, str]]:
    """Keys of the rows already in the CSV (for resuming)."""
    if not path.exists():
        return set()
    with open(path, newline="") as handle:
        return {(r["scene"], r["size"], r["method"], r["tolerance"]) for r in csv.DictReader(handle)}


def append_row(path: Path, row: dict[str, Any]) -> None:
    """Append one CSV row with a single write (header first if the file is new)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=COLUMNS, extrasaction="ignore")
    new = not path.exists() or path.stat().st_size == 0
    if new:
        writer.writeheader()
    writer.writerow({k: ("" if row.get(k) is None else row.get(k)) for k in COLUMNS})
    with open(path, "a", newline="") as handle:
        handle.write(buffer.getvalue())
        handle.flush()
        os.fsync(handle.fileno())


def problem_file(directory: Path, scene: str, size: str, params: dict[str, Any]) -> Path:
    """Assemble (once) and cache the problem of one scene and size."""
    from signorini.scenes import build_problem

    path = directory / "problems" / f"{scene}-{size}.npz"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        build_problem(scene, **params).save(path)
    return path


def run_benchmark(runs: Iterable[Run], out: Path, time_limit: float = 600.0,
                  progress: Callable[[int, int, Run, dict], None] | None = None) -> Path:
    """Run every ``run`` not yet in ``out/bench.csv``, each in its own process."""
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "bench.csv"
    runs = list(runs)
    done = done_keys(csv_path)
    todo = [r for r in runs if r.key not in done]
    for index, run in enumerate(todo, start=1):
        path = problem_file(out, run.scene, run.size, run.params)
        problem_meta = ContactProblem.load(path)
        base = {"scene": run.scene, "size": run.size, "dofs": problem_meta.n,
                "candidates": problem_meta.m, "method": run.label, "ranks": run.ranks,
                "tolerance": run.tolerance}
        command = [sys.executable, "-c", "from signorini.studies.bench import _worker_main; _worker_main()",
                   json.dumps({"problem": str(path), "method": run.method, "tolerance": run.tolerance})]
        env = None
        if run.ranks > 1:
            command, env = cluster.mpirun_command(run.ranks, command)
        try:
            proc = subprocess.run(command, capture_output=True, text=True, timeout=time_limit,
                                  env=env)
            lines = proc.stdout.strip().splitlines()
            result = json.loads(lines[-1]) if proc.returncode == 0 and lines else {
                "status": "failed", "message": (proc.stderr.strip().splitlines() or ["crashed"])[-1]}
        except subprocess.TimeoutExpired:
            result = {"status": "timeout", "message": f"no answer within {time_limit:g} s"}
        row = {**base, **result}
        append_row(csv_path, row)
        if progress is not None:
            progress(index, len(todo), run, row)
    return csv_path


# --- metrics and report ----------------------------------------------------------------------

def read_rows(path: Path) -> list[dict[str, Any]]:
    """The CSV's rows with numbers parsed."""
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        for key in COLUMNS:
            if key in ("scene", "size", "method", "tolerance", "status", "claimed_status", "message"):
                continue
            if key == "ranks" and not row.get(key):  # rows written before the column existed
                row[key] = 1.0
                continue
            try:
                row[key] = float(row[key])
            except (TypeError, ValueError):
                row[key] = float("nan")
    return rows


def shifted_geometric_mean(values: np.ndarray, shift: float = 10.0) -> float:
    """``exp(mean(log(v + shift))) − shift`` (qpbenchmark uses shift 10 on normalised times)."""
    values = np.asarray(values, dtype=float)
    return float(np.exp(np.mean(np.log(values + shift))) - shift)


def summary(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per method and tolerance: success rate, correct rate, shifted geometric mean of normalised time.

    A run's time is normalised by the best time of any method that succeeded
    on the same problem; failed runs count with the time limit's worth (10×
    the slowest success), as qpbenchmark charges them.
    """
    problems = {(r["scene"], r["size"]) for r in rows}
    best = {}
    for key in problems:
        ok = [r["time_s"] for r in rows if (r["scene"], r["size"]) == key and r["status"] == "converged"]
        best[key] = (min(ok), max(ok)) if ok else (np.nan, np.nan)
    out = []
    for method, tolerance in sorted({(r["method"], r["tolerance"]) for r in rows}):
        mine = [r for r in rows if r["method"] == method and r["tolerance"] == tolerance]
        success = [r["status"] == "converged" for r in mine]
        correct = [(r["claimed_status"] == "converged") == (r["status"] == "converged") for r in mine]
        normalised = []
        for r in mine:
            fastest, slowest = best[(r["scene"], r["size"])]
            time_s = r["time_s"] if r["status"] == "converged" else 10 * slowest
            normalised.append(time_s / fastest)
        out.append({"method": method, "tolerance": tolerance, "runs": len(mine),
                    "success_rate": float(np.mean(success)), "correct_rate": float(np.mean(correct)),
                    "shifted_gmean_time": shifted_geometric_mean(np.array(normalised))})
    return out


def write_report(csv_path: Path, command: str) -> Path:
    """``bench.md`` and figures next to the CSV."""
    from signorini.files import atomic_write_text, save_figure
    from signorini.output import plots
    from signorini.output.report import provenance

    rows = read_rows(csv_path)
    if not rows:
        raise InputError(f"{csv_path} has no rows to report")
    directory = csv_path.parent
    info = provenance()
    ax = plots.bench_speed_accuracy(rows, metric="kkt_worst")
    save_figure(ax.figure, directory / "speed-vs-kkt.png")
    ax = plots.bench_speed_accuracy(rows, metric="p0_rel")
    save_figure(ax.figure, directory / "speed-vs-p0.png")
    ax, slopes = plots.bench_time_vs_dofs(rows)
    save_figure(ax.figure, directory / "time-vs-dofs.png")
    md = ["# signorini benchmark", "", f"Command: `{command}`  ",
          f"Machine: {info['cpu']}, {info['cores']} cores, Python {info['python']}, {info['date']}  ",
          "Versions: " + ", ".join(f"{k} {v}" for k, v in info["versions"].items()), "",
          "Each run in its own process; `ratio` is the run's time over one factorisation + solve "
          "of the same K with the same backend, measured in the same process; the time is the "
          "method's alone (not the certificate that judges it). `λ vs exact` and `misclassified` "
          f"compare with the exact answer of `{REFERENCE}` (certified like every run).", "",
          "## Summary by method and tolerance", "",
          "| method | tolerance | runs | success rate | correct rate | shifted geometric mean of normalised time |",
          "|---|---|---:|---:|---:|---:|"]
    for s in summary(rows):
        md.append(f"| {s['method']} | {s['tolerance']} | {s['runs']} | {s['success_rate']:.0%} | "
                  f"{s['correct_rate']:.0%} | {s['shifted_gmean_time']:.2f} |")
    md += ["", "## Every run", "",
           "| size | dofs | method | tol | status (claimed) | iterations | time [s] | ratio to one factorisation | worst KKT | λ vs exact | misclassified | p0 err |",
           "|---|---:|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        status = r["status"] if r["claimed_status"] in (r["status"], "") else f"{r['status']} ({r['claimed_status']})"
        md.append(f"| {r['size']} | {r['dofs']:.0f} | {r['method']} | {r['tolerance']} | {status} | "
                  f"{r['iterations']:.0f} | {r['time_s']:.3g} | {r['ratio_to_factor']:.3g} | "
                  f"{r['kkt_worst']:.1e} | {r['lam_rel']:.1e} | {r['misclassified']:.0f} | {r['p0_rel']:.2e} |")
    md += ["", "## Time against dofs (fitted log–log slopes)", ""]
    md += [f"- {label}: slope {slope:.2f}" for label, slope in slopes.items()]
    md += ["", "![speed vs KKT](speed-vs-kkt.png)", "", "![speed vs p0](speed-vs-p0.png)", "",
           "![time vs dofs](time-vs-dofs.png)", ""]
    path = directory / "bench.md"
    atomic_write_text(path, "\n".join(md) + "\n")
    return path
