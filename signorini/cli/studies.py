"""The study commands: ``converge``, ``validate``, ``sweep``, ``stability``."""

from __future__ import annotations

import argparse
import shlex
import sys

from signorini.errors import InputError
from signorini.solvers.options import guess_value
from signorini.cli.common import (EXIT_FAILED, OPT_METAVAR, PROBLEM_FILES, add_command, family_of,
                                  input_files, method_options, out_folder, pairs, parse_time_limit,
                                  parse_tol, user_methods_in_workers, write_output)


def cmd_converge(args: argparse.Namespace) -> int:
    # each command loads what it needs (the studies start matplotlib)
    from signorini.files import all_or_none
    from signorini.studies.convergence import check_study, grading_comparison, run_study  # as above
    from signorini.studies.convergence_report import study_table, write_study  # as above

    if args.uniform_levels is not None and not 0 <= args.uniform_levels <= 4:
        raise InputError(f"--uniform-levels {args.uniform_levels} must be in 0..4")
    out = out_folder(args.out, input_files(args.scene, args.method))
    scene, params = family_of(args.scene, pairs(args.set, "--set"), "converge")
    check_study(scene, args.levels, params, args.method or None, args.fit_from)
    say = (lambda line: print(line, file=sys.stderr))
    with user_methods_in_workers(args.method):  # a user's method runs in a worker process
        study = run_study(scene, args.levels, params, methods=args.method or None,
                          fit_from=args.fit_from, progress=say)
    comparison = None
    if args.uniform_levels is not None:
        comparison = grading_comparison(scene, study, args.uniform_levels, params, progress=say)
    command = "signorini converge " + " ".join(shlex.quote(a) for a in sys.argv[2:]) \
        if len(sys.argv) > 2 and sys.argv[1] == "converge" else f"signorini converge {args.scene} --levels {args.levels}"
    with all_or_none():  # the whole report, or none of it
        paths = write_study(study, out, command, comparison)
    print("\n".join(study_table(study)))
    if comparison is not None:
        print(f"{comparison.metric} {100 * comparison.target:g} %: graded {comparison.graded_dofs:,.0f} dofs "
              f"({comparison.graded_how}), uniform {comparison.uniform_dofs:,.0f} dofs "
              f"({comparison.uniform_how}): grading saves {comparison.saving:,.0f}×")
    print(f"report: {paths['markdown']}")
    never = [m for m in args.method if not any(r.method == m and r.status == "converged"
                                               for r in study.rows)]
    if never:
        print(f"signorini: {', '.join(never)} converged at no level", file=sys.stderr)
        return EXIT_FAILED
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    # each command loads what it needs (the report starts matplotlib)
    import os

    from signorini.files import all_or_none, check_outputs  # as above
    from signorini.output.ci import github_annotations, junit_xml  # as above
    from signorini.output.report import REPORT_FILES, checks_summary, write_suite_report  # as above
    from signorini.problem.files import problem_file_paths, read_problem  # as above
    from signorini.solvers.registry import check_request  # as above
    from signorini.studies.suite import problem_case, run_suite, select_cases  # as above
    from signorini.studies.suite_checks import TIGHT_TOL, read_limits  # as above

    time_limit = parse_time_limit(args.time_limit)
    tol = TIGHT_TOL if args.tol is None else parse_tol(args.tol)
    methods = args.method or None
    inputs = input_files(methods=args.method)
    for path in args.problem:
        inputs.update({f"problem file {p}": p for p in problem_file_paths(path)})
    if args.limits:
        inputs["limits file"] = args.limits
    outputs = check_outputs({"--junit": args.junit}, {"--out": args.out}, inputs=inputs,
                            fills={"--out": REPORT_FILES})
    out = outputs["--out"]
    if args.junit == "-":  # the summary and the annotations are printed there
        raise InputError("--junit - would mix the XML with the summary on stdout: give a file "
                         "name, e.g. --junit report.xml")
    options = {name: {key: guess_value(value) for key, value in given.items()}
               for name, given in method_options(args.opt, args.method).items()}
    for name in args.method or list(options):
        check_request(name, options=options.get(name))  # refused before any work
    limits = read_limits(args.limits) if args.limits else None
    for path in args.problem:
        read_problem(path)  # a bad file is refused before any run, in one line
    cases = select_cases(args.case) if args.case or not args.problem else ()
    files: dict[str, str] = {}
    for path in args.problem:
        case = problem_case(path, [c.name for c in cases])
        cases += (case,)
        files[case.name] = path
    limit = {} if time_limit is None else {"time_limit": time_limit}
    suite = run_suite(cases, method_names=methods,
                      progress=lambda line: print(line, file=sys.stderr), tol=tol,
                      options=options, limits=limits, **limit)
    command = "signorini validate" + "".join(f" --method {shlex.quote(m)}" for m in args.method)
    command += "".join(f" --case {c}" for c in args.case)
    command += "".join(f" --problem {shlex.quote(p)}" for p in args.problem)
    command += "".join(f" --opt {shlex.quote(o)}" for o in args.opt)
    for flag, value in (("--tol", args.tol), ("--limits", args.limits),
                        ("--time-limit", args.time_limit), ("--junit", args.junit)):
        if value is not None:
            command += f" {flag} {shlex.quote(value)}"
    if args.out != "validation-report":
        command += f" --out {shlex.quote(args.out)}"
    with all_or_none():  # the whole report (and the JUnit file), or none of it
        paths = write_suite_report(suite, out, command)
        if outputs["--junit"]:
            write_output(outputs["--junit"], junit_xml(suite, files))
    if os.environ.get("GITHUB_ACTIONS") == "true":  # annotations on the workflow's summary
        for line in github_annotations(suite, files):
            print(line)
    print(checks_summary(suite))
    print(f"report: {paths['report.md']}")
    return 0 if suite.passed else EXIT_FAILED


def cmd_sweep(args: argparse.Namespace) -> int:
    from signorini.files import all_or_none, atomic_write_text, save_figure, to_json, writable_directory  # per command (start-up)
    from signorini.scenes import build_problem  # per command (start-up)
    from signorini.studies.sweep import parse_loads, plot_sweep, sweep_loads  # per command (start-up)

    loads = parse_loads(args.load)
    out = out_folder(args.out, input_files(args.scene))
    problem = build_problem(args.scene, params=pairs(args.set, "--set"))
    levels = sweep_loads(problem, loads, progress=lambda i, n: print(
        f"\r  load level {i}/{n}", end="" if i < n else "\n", file=sys.stderr))
    rows = [vars(level) for level in levels]
    header = list(rows[0])
    csv = "\n".join([",".join(header)] + [",".join(f"{row[k]}" for k in header) for row in rows])
    ax = plot_sweep(levels)
    ax.set_title(f"{args.scene}: {len(levels)} loads, one factorisation", fontsize=9)
    with all_or_none():  # the three files, or none of them
        directory = writable_directory(out)
        atomic_write_text(directory / "sweep.csv", csv + "\n")
        atomic_write_text(directory / "sweep.json", to_json({"scene": args.scene,
                                                             "params": problem.model.params, "levels": rows}))
        save_figure(ax.figure, directory / "sweep.png")
    print(f"{'load':>12} {'a':>12} {'a Hertz':>12} {'p0':>12} {'p0 Hertz':>12}  status")
    for lv in levels:
        print(f"{lv.total_force:12.6g} {lv.a:12.6g} {lv.a_ref or float('nan'):12.6g} "
              f"{lv.p0:12.6g} {lv.p0_ref or float('nan'):12.6g}  {lv.status}")
    for lv in levels:
        if lv.status != "converged":
            print(f"load {lv.load:g}: {lv.status}: {lv.message}")
    print(f"written: {directory / 'sweep.csv'}, sweep.json, sweep.png")
    return 0 if all(lv.status == "converged" for lv in levels) else EXIT_FAILED


def cmd_stability(args: argparse.Namespace) -> int:
    # each command loads what it needs (the atlas starts matplotlib and every backend)
    from signorini.files import all_or_none
    from signorini.studies.atlas import run_atlas, select_axes, wrapper_record, write_report  # as above

    axes = select_axes(args.axis)
    time_limit = parse_time_limit(args.time_limit)
    out = out_folder(args.out)

    def progress(axis, i, n, task, row):
        print(f"[axis {axis.number} {axis.name} {i}/{n}] {task.case} {task.method}: {row['status']} "
              f"({row.get('outcome')}) {row.get('time_s', float('nan')):.2f} s", file=sys.stderr)

    result = run_atlas(axes, quick=args.quick, isolate=not args.in_process,
                       time_limit=time_limit, progress=progress)
    command = "signorini stability" + "".join(f" --axis {a}" for a in args.axis)
    command += " --quick" * args.quick + (f" --out {shlex.quote(args.out)}"
                                          if args.out != "stability-report" else "")
    with all_or_none():  # the whole report, or none of it
        paths = write_report(result, out, command)
    right, runs, _ = wrapper_record(result.rows)
    print(f"{runs} runs in {result.elapsed_s:.0f} s; the package's status was right in "
          f"{right} of {runs}")
    print(f"report: {paths['report']}")
    return 0


def add_parsers(sub) -> None:
    """Register the study commands."""
    converge = add_command(
        sub, "converge", "refine a scene k times: errors, rates, figures",
        "Solve a scene at refinement levels 0..k with every installed exact method (or those "
        "named), fit the convergence rates of its errors against the analytic reference, and "
        "write the report (Markdown, JSON, figures) into --out.",
        ["signorini converge hertz-cylinder --levels 3",
         "signorini converge examples/hertz-cylinder.toml --levels 2 --method pdas",
         "signorini converge hertz-sphere --levels 2 --uniform-levels 1 --out conv"],
        {0: "the report was written", 1: "a method named with --method converged at no level"})
    converge.add_argument("scene", help="a scene with a 'refine' parameter (see 'signorini "
                          "scenes'), or a .toml scene file that names one (scene = \"hertz-cylinder\")")
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

    validate = add_command(
        sub, "validate", "run the validation suite on the default scenes or your problem files",
        "Run the validation suite: every case (the default scenes, or your problem files) solved "
        "by every installed method (or those named), each answer checked against its KKT "
        "certificate, the exact answer (pdas at 1e-9) and the analytic reference, within limits "
        "a --limits file may change. Writes the report into --out and, with --junit, the checks "
        "as JUnit XML for CI.",
        ["signorini validate",
         "signorini validate --problem my.npz --method mine.py:solve --junit report.xml",
         "signorini validate --case hertz-cylinder --method uzawa --opt step_fraction=0.5"],
        {0: "every check passed", 1: "a check failed (the report says which)"})
    validate.add_argument("--out", default="validation-report", help="report directory")
    validate.add_argument("--method", action="append", default=[],
                          help="only this method (repeatable; default: every installed one); "
                               "a method named here must converge on every case")
    validate.add_argument("--case", action="append", default=[],
                          help="only this case (repeatable; default: all)")
    validate.add_argument("--time-limit", metavar="SECONDS", help="seconds per run in the worker "
                          "process (default 600): a method that hangs costs its limit")
    validate.add_argument("--problem", action="append", default=[], metavar="FILE",
                          help=f"a problem file of yours (repeatable): {PROBLEM_FILES}; only "
                               "these unless --case")
    validate.add_argument("--tol", help="the relative KKT tolerance asked of every method "
                          "(default 1e-9; the exact answer stays pdas at 1e-9)")
    validate.add_argument("--opt", action="append", default=[], metavar=OPT_METAVAR,
                          help="an option of one method, e.g. --opt uzawa:step_fraction=0.5 "
                               "(KEY=VALUE alone when one --method is named)")
    validate.add_argument("--limits", metavar="FILE", help="a TOML file whose [limits] table "
                          "replaces some of the checks' limits (the documentation's page ci)")
    validate.add_argument("--junit", metavar="FILE", help="also write the checks as JUnit XML "
                          "for CI, e.g. report.xml; under GitHub Actions failed checks are "
                          "also annotations")
    validate.set_defaults(run=cmd_validate)

    sweep = add_command(
        sub, "sweep", "solve many load levels with one factorisation",
        "Solve one scene at n load levels with one factorisation of K, and write sweep.csv, "
        "sweep.json and sweep.png into --out: the contact half-width and peak pressure at each "
        "level beside Hertz's.",
        ["signorini sweep hertz-cylinder --load 0.001:0.004:4",
         "signorini sweep hertz-sphere --load 1e-4:1e-3:5 --out sweep"],
        {0: "every load level converged", 1: "a level did not (printed after the table)"})
    sweep.add_argument("scene", help="scene name (see 'signorini scenes')")
    sweep.add_argument("--load", required=True, metavar="P1:P2:n",
                       help="n loads from P1 to P2 (per unit thickness of the full body)")
    sweep.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="scene parameter, e.g. --set n_contact=80")
    sweep.add_argument("--out", default="sweep-report", help="output directory")
    sweep.set_defaults(run=cmd_sweep)

    stability = add_command(
        sub, "stability", "the stability atlas: where each method fails",
        "The stability atlas: every method run along eight axes (tolerance, mesh size, load, "
        "Poisson's ratio and more) to where it fails, each run judged by the certificate; the "
        "report says where each method fails and whether the package's status said so.",
        ["signorini stability --quick", "signorini stability --axis 1 --axis 2 --out atlas"],
        {0: "the atlas was written (its report says where methods fail)"})
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


__all__ = ["cmd_converge", "cmd_validate", "cmd_sweep", "cmd_stability", "add_parsers"]
