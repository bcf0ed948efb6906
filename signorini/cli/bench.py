"""``signorini bench``: methods × sizes × tolerances, or a peer side by side (``--peer``)."""

from __future__ import annotations

import argparse
import os
import shlex
import sys
from pathlib import Path

from signorini.errors import InputError
from signorini.cli.common import (PROBLEM_FILES, add_command, family_of, input_files, out_folder,
                                  pairs, parse_time_limit)


def _bench_peer(args: argparse.Namespace) -> int:
    # each command loads what it needs (the peer report starts matplotlib)
    from signorini.files import all_or_none  # as above
    from signorini.output.report import provenance  # as above
    from signorini.studies import peer  # as above

    points = peer.ladder([args.scene] if args.scene else list(peer.ONE_BODY),
                         None if args.sizes is None else _sizes(args.sizes, ""), pairs(args.set, "--set"))
    out = out_folder(args.out or "peer-report")
    missing = peer.getfem_missing()
    if missing:  # skipped with a word where GetFEM is not installed
        print(f"signorini: {missing}; the peer benchmark is skipped, nothing written")
        return 0
    load = {"before": os.getloadavg()}
    rows = peer.run_peer(points, repeat=args.repeat, in_process=args.in_process,
                         timeout=parse_time_limit(args.time_limit),
                         progress=lambda line: print(line, file=sys.stderr))
    load["after"] = os.getloadavg()
    given = " ".join(shlex.quote(a) for a in sys.argv[2:]) if sys.argv[1:2] == ["bench"] else ""
    meta = {"machine": provenance(), "repeat": args.repeat, "in_process": args.in_process,
            "getfem_python": peer.system_python(),
            "load_average": load,
            "signorini_command": peer.our_command(), "PYTHONPATH": os.environ.get("PYTHONPATH"),
            "getfem": next((r["versions"]["getfem"] for r in rows if "versions" in r), None)}
    with all_or_none():  # the whole report, or none of it
        paths = peer.write_peer(rows, out, f"signorini bench {given or '--peer getfem'}", meta)
    print("\n".join(peer.peer_table(rows)))
    print(f"report: {paths['md']}")
    return 0


def _sizes(text: str | None, default: str) -> list[int]:
    """``--sizes`` as distinct levels (``default`` when not given; an empty list is refused)."""
    try:
        levels = [int(x) for x in (default if text is None else text).split(",")]
    except ValueError:
        raise InputError(f"--sizes {text!r} is not a comma-separated list of sizes, "
                         "e.g. --sizes 0,1,2") from None
    if len(set(levels)) != len(levels):
        raise InputError(f"--sizes {text!r} names a size twice: give each once, e.g. --sizes 0,1")
    return levels


def cmd_bench(args: argparse.Namespace) -> int:
    if args.repeat < 1:
        raise InputError(f"--repeat {args.repeat} must be at least 1")
    if args.in_process < 0:
        raise InputError(f"--in-process {args.in_process} must be 0 (not timed in process) or more, "
                         "e.g. --in-process 5")
    if args.default_only_from is not None and args.default_only_from < 0:
        raise InputError(f"--default-only-from {args.default_only_from} must be a refinement "
                         "level >= 0, e.g. --default-only-from 3")
    if args.peer and args.problem:
        raise InputError("--peer runs GetFEM on its own Hertz scenes: drop --problem (or --peer)")
    if args.peer:
        return _bench_peer(args)
    # each command loads what it needs (the benchmark's report starts matplotlib)
    from signorini.files import all_or_none, writable_directory
    from signorini.problem.files import read_problem  # as above
    from signorini.scenes import get_scene  # as above
    from signorini.scenes.size import check_size  # as above
    from signorini.solvers.registry import check_request, methods  # as above
    from signorini.studies.bench import (TOLERANCES, Run, check_csv, run_benchmark,  # as above
                                          write_report)

    if args.problem is not None:  # a problem file is one size, solved as stored
        given = [flag for flag, on in (("--scene", args.scene), ("--sizes", args.sizes),
                                       ("--set", args.set),
                                       ("--default-only-from", args.default_only_from is not None))
                 if on]
        if given:
            raise InputError(f"{given[0]} builds a scene, and --problem {args.problem!r} is solved "
                             f"as stored: drop {given[0]}")
        problem = read_problem(args.problem)  # a bad file is refused before any work
        family, levels = None, [0]
    else:
        scene, base = family_of(args.scene or "hertz-cylinder", pairs(args.set, "--set"), "bench")
        family = get_scene(scene)
        levels = _sizes(args.sizes, "0,1")
        refine = next((p for p in family.params if p.name == "refine"), None)
        wrong = [(level, refine.check(level)) for level in levels if refine and refine.check
                 and refine.check(level)]
        if refine is None:
            raise InputError(f"--scene {family.name}: bench sizes a scene by its parameter "
                             "refine, which this one has not: choose a scene with it (see "
                             "'signorini scenes'), or give --problem a saved problem of it")
        if wrong:
            raise InputError(f"--sizes {args.sizes!r}: level {wrong[0][0]} must be {wrong[0][1]} "
                             f"(the refinements of {family.name}), e.g. --sizes 0,1")
    time_limit = parse_time_limit(args.time_limit)
    tolerances = args.tol.split(",")
    unknown = [t for t in tolerances if t not in TOLERANCES]
    if unknown:
        raise InputError(f"--tol {unknown[0]!r} is not one of {', '.join(TOLERANCES)}: give "
                         "levels, e.g. --tol mid,high")
    inputs = input_files(args.problem, args.method)
    out = out_folder(args.out or "bench-report", inputs)
    csv_path = Path(out) / "bench.csv"
    if args.report_only and not csv_path.is_file():
        raise InputError(f"--report-only: there is no {csv_path}: run the benchmark into --out "
                         f"{args.out or 'bench-report'} first (without --report-only)")
    if csv_path.exists():  # read before a run is appended to it or a report made of it
        check_csv(csv_path)
    # a method that is named must be installed, as for 'solve --method'
    chosen = [check_request(m)[0] for m in args.method] if args.method else \
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
    runs = []
    for level in levels:
        if family is None:
            params, scene, size = {}, problem.name or Path(args.problem).stem, "file"
        else:
            params, scene, size = {**base, "refine": level}, family.name, f"refine{level}"
            check_size(family.name, family.parse(params))  # bad or too big: refused before any run
        for method in chosen:
            few = args.default_only_from is not None and level >= args.default_only_from
            for tolerance in (["high"] if method.exact else ["default"] if few else tolerances):
                for count in (ranks if method.family == "petsc" else [1]):
                    runs.append(Run(scene, size, params, method.name, tolerance, ranks=count,
                                    source=args.problem and os.path.abspath(args.problem)))

    def progress(i, n, run, row):
        print(f"[{i}/{n}] {run.size} {run.label}@{run.tolerance}: {row['status']} "
              f"{row.get('time_s', float('nan')):.3g} s", file=sys.stderr)

    if not args.report_only:  # the CSV grows run by run (resumable): the folder is made now
        run_benchmark(runs, writable_directory(out), time_limit=time_limit, progress=progress)
    given = [a for a in sys.argv[2:] if a != "--report-only"]  # the command that made the CSV
    command = "signorini bench " + " ".join(given) if given else "signorini bench"
    with all_or_none():  # the report and its figures, or none of them
        try:
            report = write_report(csv_path, command)
        except InputError:
            raise
        except (KeyError, ValueError, TypeError) as exc:  # a row bench did not write
            raise InputError(f"{csv_path} holds a row the benchmark did not write ({type(exc).__name__}"
                             f": {exc}): fix or remove the row, or run into another --out") from None
    print(f"report: {report}")
    return 0


def add_parsers(sub) -> None:
    """Register ``bench``."""
    bench = add_command(
        sub, "bench", "benchmark methods × sizes × tolerances (resumable CSV)",
        "Benchmark methods × sizes × tolerances on a scene at several refinements (or on a "
        "problem file), each run in a process of its own within a time limit: one row per run "
        "in a resumable CSV, then a report (bench.md) and figures in --out. --peer getfem runs "
        "GetFEM on the Hertz scenes beside this package.",
        ["signorini bench --sizes 0,1 --method pdas --method qp-osqp",
         "signorini bench --problem my.npz --tol mid,high --out bench",
         "signorini bench --peer getfem --sizes 0,1"],
        {0: "the report was written (a run that failed is a row of it)"})
    bench.add_argument("--scene", help="default hertz-cylinder (with --peer: hertz-cylinder and "
                       "hertz-sphere; or hertz-two-cylinders)")
    bench.add_argument("--problem", metavar="FILE", help="benchmark on a problem file of yours "
                       f"instead of a scene: {PROBLEM_FILES}")
    bench.add_argument("--sizes", help="refinement levels, e.g. 0,1,2 (default 0,1; with --peer: "
                       "rungs of the peer ladder 0..4, 0..3 for hertz-two-cylinders; default all)")
    bench.add_argument("--peer", choices=["getfem"], help="the Hertz scenes by GetFEM (system "
                       "python3-getfem) and this package side by side: accuracy, whole-process time")
    bench.add_argument("--repeat", type=int, default=5,
                       help="with --peer: whole-process runs per point, the fastest kept (default 5)")
    bench.add_argument("--in-process", type=int, default=5, metavar="N",
                       help="with --peer: solves per point in one process after a warm-up, the "
                            "fastest kept (default 5; 0: whole process only)")
    bench.add_argument("--method", action="append", default=[],
                       help="only this method (repeatable; default: every installed sparse one)")
    bench.add_argument("--tol", default="low,mid,high,default", metavar="LEVELS",
                       help="the tolerances asked of the iterative methods, as levels: low (1e-3), "
                            "mid (1e-6), high (1e-9), default (the method's own); default all four")
    bench.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    bench.add_argument("--default-only-from", type=int, default=None, metavar="LEVEL",
                       help="from this refinement level on, iterative methods run at their "
                            "default tolerance only (large sizes)")
    bench.add_argument("--time-limit", default="600", help="seconds per run")
    bench.add_argument("--ranks", default="1", help="MPI ranks for the petsc methods, e.g. 1,2 "
                       "(each count is one more run; never more than the cores)")
    bench.add_argument("--out", help="default bench-report (with --peer: peer-report)")
    bench.add_argument("--report-only", action="store_true", help="rewrite the report from the CSV")
    bench.set_defaults(run=cmd_bench)


__all__ = ["cmd_bench", "add_parsers"]
