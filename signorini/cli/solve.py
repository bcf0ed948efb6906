"""``signorini solve``: one scene, one method."""

from __future__ import annotations

import argparse
import os
import sys

from signorini.cli.common import (EXIT_FAILED, OPT_METAVAR, SCENE_HELP, add_command, input_files,
                                  method_options, pairs, parse_time_limit, parse_tol, process_seconds,
                                  stdout_to_stderr, write_output)
from signorini.errors import InputError
from signorini.solvers.options import DEFAULT_TOL, guess_value


def cmd_solve(args: argparse.Namespace) -> int:
    from signorini.api import Result, solve, solve_adaptive, solve_summary  # per command
    from signorini.scenes import build_problem  # per command (start-up)
    from signorini.files import STDOUT, all_or_none, check_outputs, to_json  # per command (start-up)
    from signorini.certification.kkt import Certificate, certificate  # per command (start-up)
    from signorini.problem.files import is_problem_file  # per command (start-up)
    from signorini.solvers.registry import check_request, get_method  # per command (start-up)
    from signorini.solvers import user  # per command (start-up)
    from signorini.numerics.factor import timed  # per command (start-up)

    # the process's start-up (interpreter, imports, parsing), when this command is the process
    startup = process_seconds() if getattr(args, "process", False) else None
    params = pairs(args.set, "--set")
    texts = method_options(args.opt, [args.method]).get(args.method, {})
    max_iter = guess_value(texts.pop("max_iter")) if "max_iter" in texts else None
    tol = parse_tol(args.tol) if args.tol is not None else None
    inputs = input_files(args.scene, [args.method])  # before the method's file is imported
    from_file = is_problem_file(args.scene)
    if from_file:  # a problem file is solved as stored: nothing to build, refine or rescale
        given = [flag for flag, on in (("--set", args.set), ("--raw-units", args.raw_units),
                                       ("--target-error", args.target_error is not None)) if on]
        if given:
            raise InputError(f"{given[0]} applies to a scene; problem file {args.scene!r} is "
                             f"solved as stored: drop {given[0]}")
    # every option read as its declared kind and checked before the scene is built
    # a method of the user's is imported in the worker process that runs it, not here
    method = user.deferred(args.method) if ":" in args.method else get_method(args.method)
    request = check_request(method, tol, max_iter, method.parse_options(texts))  # once: solve takes it
    time_limit = parse_time_limit(args.time_limit)
    if time_limit is not None and args.target_error is not None:
        raise InputError("--time-limit runs one solve in a worker process and --target-error "
                         "refines in this one: give one of them")
    if args.target_error is None and (args.max_dofs is not None or args.target_on is not None):
        given = "--max-dofs (max_dofs)" if args.max_dofs is not None else "--target-on (target_on)"
        raise InputError(f"{given} steers adaptive refinement: give --target-error (target_error) "
                         "with it")
    # a method of the user's runs in a worker process: whatever it does to its process (exits,
    # closes stdout, changes folder, prints) costs its run only, never this one's exit code
    if method.family == "user" and args.target_error is not None:
        raise InputError(f"--method {args.method} runs in a worker process and --target-error "
                         "refines in this one: drop --target-error")
    if method.family == "user" and time_limit is None:
        time_limit = float("inf")
    if args.vtk:
        from signorini.output.export import check_vtk_path  # per command (start-up)

        check_vtk_path(args.vtk)  # a bad export path fails before the solve
    outputs = check_outputs({"--json": args.json, "--vtk": args.vtk}, inputs=inputs)
    json_path, vtk_path = outputs["--json"], outputs["--vtk"]
    with stdout_to_stderr(json_path == STDOUT):  # what a method prints cannot corrupt the JSON
        if args.target_error is not None:  # adaptive refinement (signorini.scenes.adapt)
            if args.raw_units:
                raise InputError("--target-error refines a non-dimensionalised scene: drop --raw-units")
            result = solve_adaptive(args.scene, args.target_error, request, params=params,
                                    max_dofs=args.max_dofs, target_on=args.target_on)
            problem = result.problem
        else:
            problem = build_problem(args.scene, params=params, nondimensionalise=not args.raw_units,
                                    solved_by=method)
            if vtk_path and problem.model.mesh is None:
                raise InputError(f"--vtk writes the mesh, and {args.scene!r} holds none (a QP "
                                 "given as arrays): drop --vtk, or save the problem of a scene")
            if time_limit is None:
                result = solve(problem, request)
                problem = result.problem
            else:  # in a worker process that is stopped after the limit (signorini.studies.worker)
                from signorini.studies.runner import solve_within  # per command (start-up)

                # the worker builds the problem again and solves it as signorini.solve does (load
                # control with the scene's predictions, then the method), and says the push matched
                spec = {"kind": "stored", "path": os.path.abspath(args.scene)} if from_file else \
                    {"kind": "scene", "scene": args.scene, "params": params,
                     "nondimensionalise": not args.raw_units}
                seconds: dict[str, float] = {}
                with timed(seconds, "method"):  # the worker's whole run, its start-up included
                    solution = solve_within(problem, {**spec, "matched": False}, args.method,
                                            time_limit, tol=tol, max_iter=max_iter,
                                            options=request.options)
                push, given = (solution.extras.pop(said, None) for said in ("push", "certificate"))
                if problem.model.pending and push is not None:
                    problem = problem.pushed(float(push))
                with timed(seconds, "certificate"):  # the worker's, on the same arrays
                    judged = certificate(problem, solution) if given is None else Certificate(**given)
                solution.seconds = {**solution.seconds, **seconds}
                result = Result(problem, solution, judged)
    if startup is not None:
        result.solution.seconds["startup"] = startup
    finite = result.finite
    with all_or_none():  # every output, or none of them
        if vtk_path and finite:  # before the record, whose output stage counts it
            from signorini.output.export import export_vtk  # per command (start-up)

            with timed(result.solution.seconds, "output"):
                export_vtk(problem, result.solution, vtk_path)
        record = result.to_dict()
        if json_path:
            write_output(json_path, to_json(record) + "\n")
    if json_path != STDOUT:
        print(solve_summary(record))
    if vtk_path and not finite:
        print(f"signorini: no finite answer, {args.vtk} not written", file=sys.stderr)
        return EXIT_FAILED
    if vtk_path:
        print(f"written: {args.vtk}", file=sys.stderr if json_path == STDOUT else sys.stdout)
    if result.target_met is False:
        print(f"signorini: the target error was not met ({result.solution.extras['adaptive'][-1]['action']}"
              "): raise --max-dofs or relax --target-error; the last mesh's answer is reported",
              file=sys.stderr)
    return 0 if result.converged and result.target_met is not False else EXIT_FAILED


def add_parsers(sub) -> None:
    """Register ``solve``."""
    solve = add_command(
        sub, "solve", "solve one scene with one method",
        "Solve one scene (by name or from a .toml scene file) or one problem file with one "
        "method, and print the summary: the method's status, the independent KKT certificate "
        "that backs it, the contact and, for a scene with an analytic reference, its errors "
        "against it. --json writes the whole record, --vtk the mesh and fields for ParaView.",
        ["signorini solve hertz-cylinder",
         "signorini solve examples/hertz-cylinder.toml --method qp-clarabel --tol 1e-9 --json r.json",
         "signorini solve my.npz --method mine.py:solve --time-limit 60"],
        {0: "the method converged and the certificate agrees",
         1: "it did not (failed, max_iter, inaccurate), --target-error was not met, or --vtk had "
            "no finite answer to write"})
    solve.add_argument("scene", help=SCENE_HELP)
    solve.add_argument("--method", default="auto",
                       help="method name (see 'signorini methods'; auto: pdas in 2D, pdas-amg for large 3D)")
    solve.add_argument("--tol", help="the method's tolerance (default: the method's own; a QP "
                       f"backend runs at its own settings, its answer held to {DEFAULT_TOL:g})")
    solve.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="scene parameter, e.g. --set a_over_R=0.05")
    solve.add_argument("--opt", action="append", default=[], metavar=OPT_METAVAR,
                       help="method option, e.g. --opt step_fraction=0.5 (METHOD: may name the "
                            "--method, as in crosscheck and validate)")
    solve.add_argument("--json", metavar="FILE", help="write the result as JSON ('-' for stdout)")
    solve.add_argument("--raw-units", action="store_true",
                       help="solve in the user's units instead of non-dimensionalising")
    solve.add_argument("--vtk", metavar="FILE",
                       help="write the mesh (undeformed: ParaView's Warp By Vector on displacement "
                            "deforms it) with displacement, stress, gap and pressure (.vtu or .vtk)")
    solve.add_argument("--target-error", metavar="ETA", help="refine adaptively until the estimated "
                       "relative error is at most ETA (0.01 or 1%%): of the contact pressure, or "
                       "see --target-on")
    solve.add_argument("--target-on", choices=["pressure", "energy"], help="with --target-error: "
                       "the contact pressure's L2 error (default, 2D scenes) or the energy norm's")
    solve.add_argument("--time-limit", metavar="SECONDS", help="solve in a worker process that is "
                       "stopped after SECONDS (assembly included): a method that hangs or exits "
                       "costs its limit and ends 'failed'")
    solve.add_argument("--max-dofs", type=int, metavar="N", help="with --target-error: no mesh "
                       "beyond N dofs (default 100000)")
    solve.set_defaults(run=cmd_solve)


__all__ = ["cmd_solve", "add_parsers"]
