"""Benchmarks: scenes × sizes × methods × tolerance levels → one tidy CSV row per run.

Every run goes through the study runner (:mod:`signorini.studies.runner`) as a
``fresh`` task: a process of its own with a time limit, so that a backend
that hangs or crashes costs one failed row and nothing else, memory is given
back after each run and the method starts cold. Problems are assembled once
per size and stored as ``.npz`` beside the CSV (the tasks' problem specs
point at them); every row carries the time of one factorisation + solve of
the same K with the same backend, measured in the same process before the
method, so that methods are compared as ratios measured in one run. Rows are
appended one ``write`` at a time and the run resumes where it stopped: an
interrupted benchmark leaves a valid CSV.

Metrics follow qpbenchmark: a run is a *success* when the method says
``converged`` (which the package grants only when the KKT certificate is
within the tolerance); its claim is *correct* when the method's own status
and the certificate agree; times, normalised by the fastest success on the
same problem, are summarised by their shifted geometric mean (shift 10).
"""

from __future__ import annotations

import csv
import io
import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from signorini.errors import InputError
from signorini.files import all_or_none, atomic_write_text, save_figure, writable_directory
from signorini.output import plots
from signorini.output.report import status_claimed, provenance, provenance_lines
from signorini.paths import check_input_file
from signorini.reprs import markdown_table
from signorini.scenes import build_problem
from signorini.studies.runner import Row, Task, run_tasks

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
#: the columns that hold text (the others hold numbers)
TEXT_COLUMNS = ("scene", "size", "method", "tolerance", "status", "claimed_status", "message")
#: what the benchmark measures of each run besides the runner's row
MEASURES = ("factorisation", "times", "vs_reference", "reference")
#: the runner's statuses for a run that gave no answer of its own, written as "failed"
FAILED = ("refused", "input-error", "raised", "crashed")


@dataclass(frozen=True)
class Run:
    scene: str
    size: str
    params: dict[str, Any]
    method: str
    tolerance: str
    #: MPI ranks (petsc methods only; the others run in one process)
    ranks: int = 1
    #: a problem file (:mod:`signorini.problem.files`) the run solves instead of building ``scene``
    source: str | None = None

    @property
    def label(self) -> str:
        """The method as the report names it: ``petsc-vi n=2`` for 2 ranks."""
        return self.method if self.ranks == 1 else f"{self.method} n={self.ranks}"

    @property
    def key(self) -> tuple[str, str, str, str]:
        return (self.scene, self.size, self.label, self.tolerance)


def reference_policy(problem_path: Path) -> dict[str, Any]:
    """The benchmark's exact answer: :data:`REFERENCE` at the high tolerance, kept beside the problem."""
    return {"kind": REFERENCE, "tol": TOLERANCES["high"],
            "keep": str(problem_path.with_suffix(".reference.npz"))}


def task_of(run: Run, problem_path: Path) -> Task:
    """The runner's task for one run: a fresh process, the stored problem, the factorisation next to it."""
    return Task("bench", f"{run.scene} {run.size}", run.tolerance,
                {"kind": "stored", "path": str(problem_path)}, run.method,
                tol=TOLERANCES[run.tolerance], reference=reference_policy(problem_path),
                measure=MEASURES, fresh=True, ranks=run.ranks)


def bench_row(run: Run, row: Row, size: tuple[int, int]) -> Row:
    """The CSV row of a run (:data:`COLUMNS`; the method's label, its own time as ``time_s``)."""
    vs = row.get("vs_reference") or {}
    theory = row.get("reference") or {}

    def number(value: Any) -> float:
        return float("nan") if value is None else value

    out = Row(scene=run.scene, size=run.size, dofs=size[0], candidates=size[1], method=run.label,
              ranks=run.ranks, tolerance=run.tolerance,
              status="failed" if row["status"] in FAILED else row["status"],
              message=("InputError: " if row["status"] == "refused" else "") + row.get("message", ""))
    if "method_s" not in row:  # no answer: the status and the reason only
        return out
    out.update(claimed_status=row["claimed_status"], iterations=row["iterations"],
               build_s=row["build_s"], solve_s=row["solve_s"], time_s=row["method_s"],
               factor_s=row["factor_s"], ratio_to_factor=row["ratio_to_factor"],
               kkt_worst=number(row["kkt_worst"]), lam_rel=number(vs.get("lam_rel")),
               misclassified=number(vs.get("misclassified")),
               p0_rel=number(theory.get("p0_rel")), a_rel=number(theory.get("a_rel")))
    return out


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


def problem_file(directory: Path, scene: str, size: str, params: dict[str, Any],
                 source: str | None = None) -> Path:
    """Assemble (once) and store the problem of one scene and size, or of the problem file
    ``source`` (read once and stored in the package's own format)."""
    path = directory / "problems" / f"{scene}-{size}.npz"
    if not path.exists():
        writable_directory(path.parent)  # removed again at exit while empty
        build_problem(source or scene, params=None if source else params).save(path)
    return path


def stored_size(path: Path) -> tuple[int, int]:
    """``(dofs, candidates)`` of a stored problem, read without loading its matrices."""
    with np.load(path) as stored:
        n, m = (int(v) for v in stored["shape"])
    return n, m


def run_benchmark(runs: Iterable[Run], out: Path, time_limit: float = 600.0,
                  progress: Callable[[int, int, Run, dict], None] | None = None) -> Path:
    """Run every ``run`` not yet in ``out/bench.csv``, each in a process of its own."""
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "bench.csv"
    done = done_keys(csv_path)
    todo = [r for r in runs if r.key not in done]
    stored: dict[tuple[str, str], Path] = {}
    with all_or_none():  # every problem stored, or none: a later size may fail to build
        for r in todo:
            if (r.scene, r.size) not in stored:
                stored[r.scene, r.size] = problem_file(out, r.scene, r.size, r.params, r.source)
    paths = {r.key: stored[r.scene, r.size] for r in todo}
    sizes = {path: stored_size(path) for path in set(paths.values())}

    def record(index: int, count: int, task: Task, row: Row) -> None:
        run = todo[index - 1]
        written = bench_row(run, row, sizes[paths[run.key]])
        append_row(csv_path, written)
        if progress is not None:
            progress(index, count, run, written)

    run_tasks([task_of(r, paths[r.key]) for r in todo], time_limit=time_limit, progress=record)
    return csv_path


def check_csv(path: Path) -> None:
    """InputError unless ``path`` is a regular UTF-8 file whose header names the benchmark's
    columns (a CSV the benchmark wrote)."""
    check_input_file(str(path), "the benchmark's CSV", "remove it, or give another --out")
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            header = next(csv.reader(handle), [])
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{path} is not a CSV the benchmark wrote ({exc}): remove it, or give "
                         "another --out") from None
    missing = [column for column in COLUMNS if column not in header and column != "ranks"]
    if missing:
        raise InputError(f"{path} is not a CSV the benchmark wrote (no column {missing[0]!r}): "
                         "remove it, or give another --out")


# --- metrics and report ----------------------------------------------------------------------

def read_rows(path: Path) -> list[dict[str, Any]]:
    """The CSV's rows with numbers parsed."""
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        row["ranks"] = row.get("ranks") or 1.0  # rows written before the column existed
        row.update({key: _float(row[key]) for key in COLUMNS if key not in TEXT_COLUMNS})
    return rows


def _float(text: Any) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        return float("nan")


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
    rows = read_rows(csv_path)
    if not rows:
        raise InputError(f"{csv_path} has no rows to report")
    directory = csv_path.parent
    for metric, name in (("kkt_worst", "kkt"), ("p0_rel", "p0")):
        save_figure(plots.bench_speed_accuracy(rows, metric=metric).figure,
                    directory / f"speed-vs-{name}.png")
    ax, slopes = plots.bench_time_vs_dofs(rows)
    save_figure(ax.figure, directory / "time-vs-dofs.png")
    md = ["# signorini benchmark", "", f"Command: `{command}`  ",
          *provenance_lines(provenance()),
          "Each run in its own process; `ratio` is the run's time over one factorisation + solve "
          "of the same K with the same backend, measured in the same process; the time is the "
          "method's alone (not the certificate that judges it). `λ vs exact` and `misclassified` "
          f"compare with the exact answer of `{REFERENCE}` (certified like every run).", "",
          "## Summary by method and tolerance", ""]
    md += markdown_table(["method", "tolerance", "runs", "success rate", "correct rate",
                          "shifted geometric mean of normalised time"], "llrrrr",
                         ([s["method"], s["tolerance"], s["runs"], f"{s['success_rate']:.0%}",
                           f"{s['correct_rate']:.0%}", f"{s['shifted_gmean_time']:.2f}"]
                          for s in summary(rows)))
    md += ["", "## Every run", ""]
    md += markdown_table(["size", "dofs", "method", "tol", "status (claimed)", "iterations",
                          "time [s]", "ratio to one factorisation", "worst KKT", "λ vs exact",
                          "misclassified", "p0 err"], "lrlllrrrrrrr",
                         ([r["size"], f"{r['dofs']:.0f}", r["method"], r["tolerance"],
                           status_claimed(r), f"{r['iterations']:.0f}", f"{r['time_s']:.3g}",
                           f"{r['ratio_to_factor']:.3g}", f"{r['kkt_worst']:.1e}",
                           f"{r['lam_rel']:.1e}", f"{r['misclassified']:.0f}", f"{r['p0_rel']:.2e}"]
                          for r in rows))
    md += ["", "## Time against dofs (fitted log–log slopes)", ""]
    md += [f"- {label}: slope {slope:.2f}" for label, slope in slopes.items()]
    md += ["", "![speed vs KKT](speed-vs-kkt.png)", "", "![speed vs p0](speed-vs-p0.png)", "",
           "![time vs dofs](time-vs-dofs.png)", ""]
    path = directory / "bench.md"
    atomic_write_text(path, "\n".join(md) + "\n")
    return path


__all__ = ["Run", "check_csv", "reference_policy", "task_of", "bench_row", "done_keys", "append_row",
           "problem_file", "stored_size", "run_benchmark", "read_rows", "shifted_geometric_mean",
           "summary", "write_report", "TOLERANCES"]
