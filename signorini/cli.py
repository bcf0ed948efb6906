"""The ``signorini`` command: a thin shell over the library.

Bad input gives a one-line message on stderr and exit code 2; a failed
validation exits 1.
"""

from __future__ import annotations

import argparse
import logging
import os
import shlex
import sys
from pathlib import Path
from typing import Any, Sequence

from signorini.errors import InputError, SignoriniError

EXIT_FAILED, EXIT_USAGE = 1, 2


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line and exit 2, like every other bad input
        raise InputError(f"{message} (see 'signorini {self.prog.split()[-1]} --help')"
                         if " " in self.prog else f"{message} (see 'signorini --help')")


def _pairs(items: Sequence[str], flag: str) -> dict[str, Any]:
    """``key=value`` strings to a dict; values parsed as int, float, bool or left as text."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"{flag} {item!r} is not key=value: write {flag} name=value")
        out[key.strip()] = value.strip()
    return out


def _option_value(text: str) -> Any:
    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered in ("none", "null"):
        return None
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def _tol(text: str) -> float:
    from signorini.solvers.base import check_tol  # per command (start-up)

    try:
        value = float(text)
    except ValueError:
        raise InputError(f"--tol {text!r} is not a number: give e.g. --tol 1e-9") from None
    return check_tol(value, "--tol")  # the API's rule, said about the option


def _write_json(path: str, text: str) -> None:
    from signorini.files import atomic_write_text  # per command (start-up)

    if path == "-":
        sys.stdout.write(text + "\n")
    else:
        atomic_write_text(path, text + "\n")


def cmd_solve(args: argparse.Namespace) -> int:
    from signorini.api import build_problem, solve  # per command (start-up)
    from signorini.files import to_json  # per command (start-up)

    params = _pairs(args.set, "--set")
    options = {k: _option_value(v) for k, v in _pairs(args.opt, "--opt").items()}
    max_iter = options.pop("max_iter", None)
    tol = _tol(args.tol) if args.tol is not None else None
    if args.json not in (None, "-") and Path(args.json).is_dir():
        raise InputError(f"--json {args.json!r} is a directory: give a file name, "
                         f"e.g. --json {Path(args.json) / 'result.json'}")
    if args.vtk:
        from signorini.output.export import check_vtk_path  # per command (start-up)

        check_vtk_path(args.vtk)  # a bad export path fails before the solve
    if args.target_error is not None:  # adaptive refinement of the scene (signorini.scenes.adapt)
        if args.raw_units:
            raise InputError("--target-error refines a non-dimensionalised scene: drop --raw-units")
        result = solve(args.scene, args.method, tol=tol, max_iter=max_iter, params=params,
                       target_error=args.target_error, max_dofs=args.max_dofs, **options)
        problem = result.problem
    else:
        problem = build_problem(args.scene, nondimensionalise=not args.raw_units, **params)
        result = solve(problem, args.method, tol=tol, max_iter=max_iter, max_dofs=args.max_dofs,
                       **options)
    record = result.to_dict()
    if args.json:
        _write_json(args.json, to_json(record))
    if args.json != "-":
        print(result.summary())
    if args.vtk:
        from signorini.output.export import export_vtk  # per command (start-up)

        if record["contact"] is None:
            print(f"signorini: no finite answer, {args.vtk} not written", file=sys.stderr)
            return EXIT_FAILED
        export_vtk(problem, result.solution, args.vtk)
        print(f"written: {args.vtk}", file=sys.stderr if args.json == "-" else sys.stdout)
    return 0 if result.converged else EXIT_FAILED


def _check_distributed(args: argparse.Namespace, ranks: int) -> None:
    """Under mpirun only ``solve`` with a distributed (petsc-*) method makes sense."""
    from signorini.solvers.registry import get_method  # per command (start-up)

    if args.run is not cmd_solve:
        raise InputError(f"under mpirun -n {ranks} only 'signorini solve' runs: run the other "
                         "commands without mpirun")
    if get_method(args.method).family != "petsc":
        raise InputError(f"under mpirun -n {ranks} only the petsc methods run distributed: give "
                         f"--method petsc-vi (or petsc-tron, petsc-gpcg), or run {args.method} "
                         "without mpirun")


def cmd_converge(args: argparse.Namespace) -> int:
    # each command loads what it needs (the studies start matplotlib)
    from signorini.files import writable_directory
    from signorini.studies.convergence import grading_comparison, run_study, study_table, write_study  # as above

    writable_directory(args.out)
    if args.levels < 0 or args.levels > 6:
        raise InputError(f"--levels {args.levels} must be in 0..6 (each level quadruples the dofs)")
    if args.uniform_levels is not None and not 0 <= args.uniform_levels <= 4:
        raise InputError(f"--uniform-levels {args.uniform_levels} must be in 0..4")
    params = _pairs(args.set, "--set")
    say = (lambda line: print(line, file=sys.stderr))
    study = run_study(args.scene, args.levels, params, methods=args.method or None,
                      fit_from=args.fit_from, progress=say)
    comparison = None
    if args.uniform_levels is not None:
        comparison = grading_comparison(args.scene, study, args.uniform_levels, params, progress=say)
    command = "signorini converge " + " ".join(shlex.quote(a) for a in sys.argv[2:]) \
        if len(sys.argv) > 2 and sys.argv[1] == "converge" else f"signorini converge {args.scene} --levels {args.levels}"
    paths = write_study(study, args.out, command, comparison)
    print("\n".join(study_table(study)))
    if comparison is not None:
        print(f"{comparison.metric} {100 * comparison.target:g} %: graded {comparison.graded_dofs:,.0f} dofs "
              f"({comparison.graded_how}), uniform {comparison.uniform_dofs:,.0f} dofs "
              f"({comparison.uniform_how}): grading saves {comparison.saving:,.0f}×")
    print(f"report: {paths['markdown']}")
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    # each command loads what it needs (the report starts matplotlib)
    from signorini.files import writable_directory
    from signorini.output.report import checks_summary, write_suite_report  # as above
    from signorini.studies.suite import run_suite, select_cases  # as above

    writable_directory(args.out)
    methods = args.method or None
    suite = run_suite(select_cases(args.case), method_names=methods,
                      progress=lambda line: print(line, file=sys.stderr))
    command = "signorini validate" + "".join(f" --method {m}" for m in args.method)
    command += "".join(f" --case {c}" for c in args.case)
    if args.out != "validation-report":
        command += f" --out {shlex.quote(args.out)}"
    paths = write_suite_report(suite, args.out, command)
    print(checks_summary(suite))
    print(f"report: {paths['report.md']}")
    return 0 if suite.passed else EXIT_FAILED


def cmd_sweep(args: argparse.Namespace) -> int:
    from signorini.files import atomic_write_text, save_figure, to_json, writable_directory  # per command (start-up)
    from signorini.scenes import build_problem  # per command (start-up)
    from signorini.studies.sweep import parse_loads, plot_sweep, sweep_loads  # per command (start-up)

    loads = parse_loads(args.load)
    directory = writable_directory(args.out)
    problem = build_problem(args.scene, **_pairs(args.set, "--set"))
    levels = sweep_loads(problem, loads, progress=lambda i, n: print(
        f"\r  load level {i}/{n}", end="" if i < n else "\n", file=sys.stderr))
    rows = [vars(level) for level in levels]
    header = list(rows[0])
    csv = "\n".join([",".join(header)] + [",".join(f"{row[k]}" for k in header) for row in rows])
    atomic_write_text(directory / "sweep.csv", csv + "\n")
    atomic_write_text(directory / "sweep.json", to_json({"scene": args.scene, "params": problem.params,
                                                         "levels": rows}))
    ax = plot_sweep(levels)
    ax.set_title(f"{args.scene}: {len(levels)} loads, one factorisation", fontsize=9)
    save_figure(ax.figure, directory / "sweep.png")
    print(f"{'load':>12} {'a':>12} {'a Hertz':>12} {'p0':>12} {'p0 Hertz':>12}")
    for lv in levels:
        print(f"{lv.total_force:12.6g} {lv.a:12.6g} {lv.a_ref or float('nan'):12.6g} "
              f"{lv.p0:12.6g} {lv.p0_ref or float('nan'):12.6g}")
    print(f"written: {directory / 'sweep.csv'}, sweep.json, sweep.png")
    return 0


def _sizes(text: str) -> list[int]:
    try:
        return [int(x) for x in text.split(",")]
    except ValueError:
        raise InputError(f"--sizes {text!r} is not a comma-separated list of sizes, "
                         "e.g. --sizes 0,1,2") from None


def _bench_peer(args: argparse.Namespace) -> int:
    # each command loads what it needs (the peer report starts matplotlib)
    from signorini.output.report import provenance
    from signorini.studies import peer  # as above

    points = peer.ladder([args.scene] if args.scene else list(peer.SCENES),
                         None if args.sizes is None else _sizes(args.sizes), _pairs(args.set, "--set"))
    if args.repeat < 1:
        raise InputError(f"--repeat {args.repeat} must be at least 1")
    missing = peer.getfem_missing()
    if missing:  # issue 16: skipped with a word where GetFEM is not installed
        print(f"signorini: {missing}; the peer benchmark is skipped, nothing written")
        return 0
    out, load = args.out or "peer-report", {"before": os.getloadavg()}
    rows = peer.run_peer(points, repeat=args.repeat, timeout=args.time_limit,
                         progress=lambda line: print(line, file=sys.stderr))
    load["after"] = os.getloadavg()
    given = " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == ["bench"] else ""
    meta = {"machine": provenance(), "repeat": args.repeat, "getfem_python": peer.system_python(),
            "load_average": load,
            "signorini_command": peer.our_command(), "PYTHONPATH": os.environ.get("PYTHONPATH"),
            "getfem": next((r["versions"]["getfem"] for r in rows if "versions" in r), None)}
    paths = peer.write_peer(rows, out, f"signorini bench {given or '--peer getfem'}", meta)
    print("\n".join(peer.peer_table(rows)))
    print(f"report: {paths['md']}")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    if args.peer:
        return _bench_peer(args)
    import math

    # each command loads what it needs (the benchmark's report starts matplotlib)
    from signorini.files import writable_directory
    from signorini.scenes import get_scene  # as above
    from signorini.solvers.registry import get_method, methods  # as above
    from signorini.studies.bench import TOLERANCES, Run, run_benchmark, write_report  # as above

    out = writable_directory(args.out or "bench-report")
    family = get_scene(args.scene or "hertz-cylinder")
    levels = _sizes(args.sizes or "0,1")
    if not (math.isfinite(args.time_limit) and args.time_limit > 0):
        raise InputError(f"--time-limit {args.time_limit!r} must be a positive number of seconds, "
                         "e.g. --time-limit 120")
    tolerances = args.tolerance.split(",")
    unknown = [t for t in tolerances if t not in TOLERANCES]
    if unknown:
        raise InputError(f"--tolerance {unknown[0]!r} is not one of {', '.join(TOLERANCES)}")
    chosen = [get_method(m) for m in args.method] if args.method else \
        [m for m in methods(installed_only=True) if not m.dense and m.family != "user"]
    try:
        ranks = sorted({int(x) for x in args.ranks.split(",")})
    except ValueError:
        ranks = [0]
    if ranks[0] < 1:
        raise InputError(f"--ranks {args.ranks!r} must be a comma-separated list of positive "
                         "rank counts, e.g. --ranks 1,2")
    if ranks[-1] > 1:
        from signorini.solvers.cluster import mpirun_command  # only when ranks are asked for

        mpirun_command(ranks[-1], [])  # no mpirun, or more ranks than cores: fail before any run
    base = _pairs(args.set, "--set")
    runs = []
    for level in levels:
        params = {**base, "refine": level}
        family.parse(params)  # bad scene parameters fail here, before any run
        for method in chosen:
            few = args.default_only_from is not None and level >= args.default_only_from
            for tolerance in (["high"] if method.exact else ["default"] if few else tolerances):
                for count in (ranks if method.family == "petsc" else [1]):
                    runs.append(Run(family.name, f"refine{level}", params, method.name, tolerance,
                                    ranks=count))

    def progress(i, n, run, row):
        print(f"[{i}/{n}] {run.size} {run.label}@{run.tolerance}: {row['status']} "
              f"{row.get('time_s', float('nan')):.3g} s", file=sys.stderr)

    if not args.report_only:
        run_benchmark(runs, Path(out), time_limit=args.time_limit, progress=progress)
    given = [a for a in sys.argv[2:] if a != "--report-only"]  # the command that made the CSV
    command = "signorini bench " + " ".join(given) if given else "signorini bench"
    print(f"report: {write_report(Path(out) / 'bench.csv', command)}")
    return 0


def cmd_stability(args: argparse.Namespace) -> int:
    import math

    # each command loads what it needs (the atlas starts matplotlib and every backend)
    from signorini.files import writable_directory
    from signorini.studies.atlas import run_atlas, select_axes, wrapper_record, write_report  # as above

    axes = select_axes(args.axis)
    try:
        time_limit = float(args.time_limit)
    except ValueError:
        time_limit = float("nan")
    if not (math.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"--time-limit {args.time_limit!r} must be a positive number of seconds, "
                         "e.g. --time-limit 30")
    writable_directory(Path(args.out) / "stability")

    def progress(axis, i, n, task, row):
        print(f"[axis {axis.number} {axis.name} {i}/{n}] {task.case} {task.method}: {row['status']} "
              f"({row.get('outcome')}) {row.get('time_s', float('nan')):.2f} s", file=sys.stderr)

    result = run_atlas(axes, quick=args.quick, isolate=not args.in_process,
                       time_limit=time_limit, progress=progress)
    command = "signorini stability" + "".join(f" --axis {a}" for a in args.axis)
    command += " --quick" * args.quick + (f" --out {shlex.quote(args.out)}"
                                          if args.out != "stability-report" else "")
    paths = write_report(result, args.out, command)
    right, runs, _ = wrapper_record(result.rows)
    print(f"{runs} runs in {result.elapsed_s:.0f} s; the package's status was right in "
          f"{right} of {runs}")
    print(f"report: {paths['report']}")
    return 0


def cmd_scenes(args: argparse.Namespace) -> int:
    from signorini.scenes import SCENES  # per command (start-up)

    for family in SCENES.values():
        print(f"{family.name}: {family.summary}")
        for p in family.params:
            default = "—" if p.default is None else p.default
            print(f"    {p.name:<11} {str(default):<8} {p.doc}")
    return 0


def cmd_methods(args: argparse.Namespace) -> int:
    from signorini.numerics.factor import available_backends, resolve_backend  # per command (start-up)
    from signorini.solvers.registry import methods  # per command (start-up)

    print(f"factorisation backend: {resolve_backend()} (installed: {', '.join(available_backends())}; "
          "set SIGNORINI_FACTOR to choose)")
    for m in methods():
        state = "installed" if m.installed else f"not installed (pip install 'signorini[{m.extra}]')"
        kind = ", ".join(x for x in ("exact" if m.exact else "", "dense" if m.dense else "") if x)
        print(f"{m.name:<14} {state:<12} {m.summary}" + (f" [{kind}]" if kind else ""))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="signorini", description="Frictionless contact as one QP, solved many ways.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress to stderr")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    solve = sub.add_parser("solve", help="solve one scene with one method")
    solve.add_argument("scene", help="scene name (see 'signorini scenes') or a .toml scene file")
    solve.add_argument("--method", default="pdas", help="method name (see 'signorini methods')")
    solve.add_argument("--tol", help="the method's tolerance (default: the method's own)")
    solve.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="scene parameter, e.g. --set a_over_R=0.05")
    solve.add_argument("--opt", action="append", default=[], metavar="KEY=VALUE",
                       help="method option, e.g. --opt step_fraction=0.5")
    solve.add_argument("--json", metavar="FILE", help="write the result as JSON ('-' for stdout)")
    solve.add_argument("--raw-units", action="store_true",
                       help="solve in the user's units instead of non-dimensionalising")
    solve.add_argument("--vtk", metavar="FILE",
                       help="write the deformed mesh with displacement, stress, gap and pressure "
                            "(.vtu or .vtk, for ParaView)")
    solve.add_argument("--target-error", metavar="ETA", help="refine adaptively until the estimated "
                       "relative energy-norm error is at most ETA (0.01 or 1%%)")
    solve.add_argument("--max-dofs", type=int, metavar="N", help="with --target-error: no mesh "
                       "beyond N dofs (default 100000)")
    solve.set_defaults(run=cmd_solve)

    converge = sub.add_parser("converge", help="refine a scene k times: errors, rates, figures")
    converge.add_argument("scene", help="a scene with a 'refine' parameter (see 'signorini scenes')")
    converge.add_argument("--levels", type=int, default=3, help="refinements: levels 0..k (default 3)")
    converge.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                          help="scene parameter of level 0, e.g. --set n_contact=15")
    converge.add_argument("--method", action="append", default=[],
                          help="only this method (repeatable; default: every installed exact one)")
    converge.add_argument("--fit-from", type=int, default=0,
                          help="fit the rates on levels >= this one (default 0)")
    converge.add_argument("--uniform-levels", type=int, default=None, metavar="K",
                          help="also solve uniform meshes at K+1 levels and compare at equal dofs")
    converge.add_argument("--out", default="convergence-report", help="output directory")
    converge.set_defaults(run=cmd_converge)

    validate = sub.add_parser("validate", help="run the validation suite on the default scenes")
    validate.add_argument("--out", default="validation-report", help="report directory")
    validate.add_argument("--method", action="append", default=[],
                          help="only this method (repeatable; default: every installed one); "
                               "a method named here must converge on every case")
    validate.add_argument("--case", action="append", default=[],
                          help="only this case (repeatable; default: all)")
    validate.set_defaults(run=cmd_validate)

    sweep = sub.add_parser("sweep", help="solve many load levels with one factorisation")
    sweep.add_argument("scene", help="scene name (see 'signorini scenes')")
    sweep.add_argument("--load", required=True, metavar="P1:P2:n",
                       help="n loads from P1 to P2 (per unit thickness of the full body)")
    sweep.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="scene parameter, e.g. --set n_contact=80")
    sweep.add_argument("--out", default="sweep-report", help="output directory")
    sweep.set_defaults(run=cmd_sweep)

    bench = sub.add_parser("bench", help="benchmark methods × sizes × tolerances (resumable CSV)")
    bench.add_argument("--scene", help="default hertz-cylinder (with --peer: both Hertz scenes)")
    bench.add_argument("--sizes", help="refinement levels, e.g. 0,1,2 (default 0,1; with --peer: "
                       "rungs of the peer ladder 0..4, default all)")
    bench.add_argument("--peer", choices=["getfem"], help="the Hertz scenes by GetFEM (system "
                       "python3-getfem) and this package side by side: accuracy, whole-process time")
    bench.add_argument("--repeat", type=int, default=3,
                       help="with --peer: runs per point, the fastest kept (default 3)")
    bench.add_argument("--method", action="append", default=[],
                       help="only this method (repeatable; default: every installed sparse one)")
    bench.add_argument("--tolerance", default="low,mid,high,default",
                       help="tolerance levels: low (1e-3), mid (1e-6), high (1e-9), default")
    bench.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    bench.add_argument("--default-only-from", type=int, default=None, metavar="LEVEL",
                       help="from this refinement level on, iterative methods run at their "
                            "default tolerance only (large sizes)")
    bench.add_argument("--time-limit", type=float, default=600.0, help="seconds per run")
    bench.add_argument("--ranks", default="1", help="MPI ranks for the petsc methods, e.g. 1,2 "
                       "(each count is one more run; never more than the cores)")
    bench.add_argument("--out", help="default bench-report (with --peer: peer-report)")
    bench.add_argument("--report-only", action="store_true", help="rewrite the report from the CSV")
    bench.set_defaults(run=cmd_bench)

    stability = sub.add_parser("stability", help="the stability atlas: where each method fails")
    stability.add_argument("--out", default="stability-report",
                           help="writes OUT/stability.md and OUT/stability/ (runs, figures)")
    stability.add_argument("--axis", action="append", default=[],
                           help="only this axis, by number or name (repeatable; default: all 8)")
    stability.add_argument("--quick", action="store_true",
                           help="tiny meshes, few points and methods: a smoke test in seconds")
    stability.add_argument("--time-limit", default="30", help="seconds per run (default 30)")
    stability.add_argument("--in-process", action="store_true",
                           help="run in this process, without worker processes or time limits")
    stability.set_defaults(run=cmd_stability)

    sub.add_parser("scenes", help="list the scenes and their parameters").set_defaults(run=cmd_scenes)
    sub.add_parser("methods", help="list the methods and whether they are installed").set_defaults(
        run=cmd_methods)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    from signorini.solvers import cluster  # per command (start-up)

    if cluster.launched_size() > 1:
        return _main_ranks(argv)
    return _main(argv)


def _main_ranks(argv: Sequence[str] | None) -> int:
    """Under ``mpirun -n N``: rank 0 runs the command, the other ranks serve its solves."""
    from signorini.solvers import cluster  # per command (start-up)

    try:
        if cluster.rank() != 0:
            return cluster.serve()
    except ImportError:
        print("signorini: error: started by mpirun but mpi4py is not installed: "
              "pip install 'signorini[petsc]' (see README, 'PETSc and MPI')", file=sys.stderr)
        return EXIT_USAGE
    try:
        return _main(argv, ranks=cluster.size())
    finally:
        cluster.release()


def _main(argv: Sequence[str] | None, ranks: int = 1) -> int:
    try:
        args = build_parser().parse_args(argv)
        logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                            format="%(levelname)s %(name)s: %(message)s")
        if ranks > 1:
            _check_distributed(args, ranks)
        return args.run(args)
    except InputError as exc:
        print(f"signorini: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except SignoriniError as exc:
        print(f"signorini: {type(exc).__name__}: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("signorini: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. piped into `head`
        return 0


if __name__ == "__main__":
    sys.exit(main())
