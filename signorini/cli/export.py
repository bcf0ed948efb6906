"""``signorini export qpbenchmark DIR``: contact QPs as a qpbenchmark test set."""

from __future__ import annotations

import argparse

from signorini.cli.common import EXIT_FAILED, add_command, out_folder
from signorini.errors import InputError


def cmd_export_qpbenchmark(args: argparse.Namespace) -> int:
    from signorini.studies.qpbench import CERTIFIED_TOL, export  # per command (start-up)

    if args.refine < 0:
        raise InputError(f"--refine {args.refine}: give a whole number ≥ 0, e.g. --refine 1")
    folder = out_folder(args.dir)
    refs = export(folder, refine=args.refine, three_d=args.three_d, only=args.only or None)
    weak = [r.entry.name for r in refs if not r.certified]
    for r in refs:
        name, worst = r.worst()
        print(f"{r.entry.name:<13} n = {r.P.shape[0]:>7}  m = {r.G.shape[0]:>5}  "
              f"certified at {worst:.1e} ({name})")
    print(f"wrote {len(refs)} problem{'s' * (len(refs) != 1)} to {folder}: "
          f"python {folder}/signorini_contact.py run")
    if weak:
        print(f"not certified at {CERTIFIED_TOL:g}: {', '.join(weak)}")
        return EXIT_FAILED
    return 0


def add_parsers(sub) -> None:
    """Register ``export`` and its one format, ``qpbenchmark``."""
    export = add_command(
        sub, "export", "write problems for other tools (a qpbenchmark test set)",
        "Write the package's contact problems for other tools: 'signorini export qpbenchmark "
        "DIR' writes a qpbenchmark test set of contact QPs with certified answers.",
        ["signorini export qpbenchmark contact-qps",
         "signorini export qpbenchmark --help"],
        {0: "written (see the format's own help)"})
    formats = export.add_subparsers(dest="format", required=True, parser_class=type(export))
    qpb = add_command(
        formats, "qpbenchmark", "contact QPs with certified answers as a qpbenchmark test set",
        "Write a test set that qpbenchmark (pip install qpbenchmark) runs as it is: each "
        "problem's QP in qpsolvers' form (P = K, q = -f, G = N, h = d, in the scene's units) "
        "with pdas's answer, its KKT certificate and forward error (DIR/data/*.npz); "
        "DIR/signorini_contact.py (the TestSet), DIR/signorini_contact_dense.py (the dense "
        "subset) and DIR/README.md. Families: Hertz cylinder and sphere at 3 sizes, ν → ½, SI "
        "and mm–MPa units, weakly active edges, two bodies, 3D (--3d). The same command writes "
        "the same bytes.",
        ["signorini export qpbenchmark contact-qps && python contact-qps/signorini_contact.py run",
         "signorini export qpbenchmark big --refine 2 --3d --only HERTZCYL2 --only SPH3D"],
        {0: "written, and every reference answer certified at 1e-10 (relative)",
         1: "written, but some reference answer is certified only above 1e-10 (named)"})
    qpb.add_argument("dir", metavar="DIR", help="the folder to write (created; files in it replaced)")
    qpb.add_argument("--refine", type=int, default=0, metavar="R",
                     help="uniform refinements of every scene (each about 4x the unknowns in 2D; "
                          "default 0: about a minute to export)")
    qpb.add_argument("--3d", dest="three_d", action="store_true",
                     help="add the 3D sphere (SPH3D; its refinements 8x the unknowns each)")
    qpb.add_argument("--only", action="append", default=[], metavar="NAME",
                     help="only this problem, e.g. --only HERTZCYL0 (repeat)")
    qpb.set_defaults(run=cmd_export_qpbenchmark)


__all__ = ["cmd_export_qpbenchmark", "add_parsers"]
