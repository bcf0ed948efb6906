"""A snapshot of small solves over every scene and method, two snapshots compared, two trees timed.

    PYTHONPATH=TREE .venv/bin/python tools/snapshot.py record --out FILE.npz [--set mesher=relaxed]
    .venv/bin/python tools/snapshot.py compare A.npz B.npz [--out FILE.md]
    .venv/bin/python tools/snapshot.py speed OLD_TREE NEW_TREE [--rounds 5] [--out FILE.json]

``record`` solves every scene family at a small size (:func:`problem_of`) and a user's QP
(:func:`users_qp`) with every installed method through the ``signorini.solve`` on ``PYTHONPATH``:
status, iterations, time, active set, u and the contact forces λ. ``compare`` lists the pairs that
differ beyond :data:`ROUND_OFF`; ``speed`` times :data:`SPEED_CASES`, the trees alternating.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import multiprocessing
import os
import platform
import statistics
import subprocess
import sys
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

#: a difference below this (relative, max-norm) is round-off
ROUND_OFF = 1e-10
#: families whose validation case and convergence start leave them large: a coarse mesh instead
SMALL = {"hertz-sphere-3d": {"n_contact": 4, "grading": 1.0}}
USERS_QP = "from_qp"
#: the solves ``speed`` times at the scenes' defaults: (scene, method; None: the default method)
SPEED_CASES = (("hertz-cylinder", "pdas"), ("hertz-cylinder", None), (USERS_QP, "pdas"),
               ("hertz-two-cylinders", "pdas"))
#: how ``speed`` times a solve: after a smaller one in the same process, and in a fresh process;
#: with which clocks: the wall's, and the process's CPU time (less sensitive to other jobs' load)
KINDS, CLOCKS = ("warm", "cold"), ("wall", "cpu")


def users_qp(n: int = 200) -> tuple[Any, ...]:
    """A beam of ``n`` nodes on a spring bed (K ~ 1e5) pushed onto a parabola: N = −I, u ≥ −gap."""
    import scipy.sparse as sp

    x = np.linspace(0.0, 1.0, n)
    K = 1.8e5 * sp.diags([-np.ones(n - 1), 2.0 * np.ones(n) + 1e-3, -np.ones(n - 1)], [-1, 0, 1])
    f = -50.0 * np.exp(-((x - 0.5) / 0.1) ** 2)
    return K.tocsr(), f, -sp.identity(n, format="csr"), 1e-4 + 0.05 * (x - 0.5) ** 2


def problem_of(scene: str, sets: dict[str, str], small: bool = True) -> tuple[Any, dict | None]:
    """The user's QP, or the scene's name and params (small or default, with the ``--set`` ones)."""
    import signorini

    if scene == USERS_QP:
        return signorini.ContactProblem.from_qp(*users_qp(), name=USERS_QP), None
    family = signorini.scene_families()[scene]
    kinds = {p.name: p.kind for p in family.params}
    params = {**family.validation[0].params, **family.convergence_start, **SMALL.get(scene, {})}
    return scene, {**(params if small else {}), **{k: kinds[k](v) for k, v in sets.items() if k in kinds}}


def rounded_hash(values: np.ndarray) -> str:
    """sha256 (12 hex digits) of the values over their max-norm, rounded to 8 digits."""
    scale = np.max(np.abs(values)) if values.size and np.all(np.isfinite(values)) else 1.0
    rounded = np.round(values / (scale or 1.0), 8) + 0.0  # + 0.0: −0 hashes as 0
    return hashlib.sha256(rounded.tobytes()).hexdigest()[:12]


def solve_one(scene: str, method: str, sets: dict[str, str]) -> dict[str, Any]:
    """One solve through the public API, as a record's row with its arrays."""
    import signorini

    problem, params = problem_of(scene, sets)
    start = time.perf_counter()
    result = signorini.solve(problem, method, params=params)
    seconds = time.perf_counter() - start
    u, force = np.asarray(result.u, float), np.asarray(result.force, float)
    return {"status": result.status, "iterations": result.iterations, "seconds": seconds,
            "params": params, "dofs": int(u.size), "message": str(result.message)[:200],
            "active": np.flatnonzero(result.active).tolist(), "u": u, "force": force}


def run_forked(scene: str, method: str, sets: dict[str, str], timeout: float) -> dict[str, Any]:
    """:func:`solve_one` in a forked child stopped after ``timeout`` s; an exception is a status."""
    def child() -> None:
        try:
            send.send(solve_one(scene, method, sets))
        except Exception as error:
            status = "refused" if type(error).__name__ == "InputError" else "error"
            send.send({"status": status, "message": f"{type(error).__name__}: {error}"[:200]})

    receive, send = multiprocessing.Pipe(duplex=False)
    process = multiprocessing.get_context("fork").Process(target=child)
    process.start()
    row = receive.recv() if receive.poll(timeout) else {"status": "timeout", "message": f"over {timeout:g} s"}
    process.terminate()
    process.join()
    return row


def machine(tree: Path) -> dict[str, Any]:
    """Where a run is made: the tree and its commit, the machine, its load average, the date."""
    git = ["git", "-C", str(tree), "rev-parse", "--short", "HEAD"]
    return {"tree": str(tree), "commit": subprocess.run(git, capture_output=True, text=True).stdout.strip(),
            "machine": f"{platform.node()}: {platform.processor() or platform.machine()}, "
                       f"{os.cpu_count()} cores, Python {platform.python_version()}",
            "load": [round(x, 2) for x in os.getloadavg()],
            "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}


def record(out: Path, sets: dict[str, str], timeout: float) -> None:
    import signorini

    meta, arrays = {**machine(Path(signorini.__file__).resolve().parents[1]), "sets": sets, "rows": []}, {}
    for scene, method in itertools.product([*signorini.scene_families(), USERS_QP],
                                           [m.name for m in signorini.methods(installed_only=True)]):
        row = {"scene": scene, "method": method, **run_forked(scene, method, sets, timeout)}
        for name in ("u", "force"):
            values = np.asarray(row.pop(name, np.zeros(0)), float)
            arrays[f"{name}|{scene}|{method}"] = values
            row[f"{name}_norm"] = float(np.max(np.abs(values))) if values.size else None
            row[f"{name}_hash"] = rounded_hash(values)
        meta["rows"].append(row)
        print(f"{scene} {method}: {row['status']} {row.get('seconds', 0):.2f} s", file=sys.stderr)
    meta["load_after"] = [round(x, 2) for x in os.getloadavg()]
    save(out, meta, arrays)


def save(out: Path, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    """A record: .json holds the rows alone (norms and hashes), .npz the rows and the arrays."""
    out.parent.mkdir(parents=True, exist_ok=True)
    text, as_json = json.dumps(meta, indent=1, default=float), out.suffix == ".json"
    out.write_text(text + "\n") if as_json else np.savez_compressed(out, meta=np.array(text), **arrays)


def load(path: Path) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """A record's metadata and its arrays (none for a .json record)."""
    if path.suffix == ".json":
        return json.loads(path.read_text()), {}
    with np.load(path) as data:
        return json.loads(str(data["meta"])), {k: data[k] for k in data.files if k != "meta"}


def relative(a: np.ndarray | None, b: np.ndarray | None, norms: tuple) -> float | str:
    """max|a − b| / max|a|; from the norms alone for a .json record; a change of size as text."""
    if a is None or b is None:
        return float("nan") if None in norms else abs(norms[0] - norms[1]) / (abs(norms[0]) or 1.0)
    if a.shape != b.shape:
        return f"{a.size} → {b.size} values"
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return 0.0 if np.array_equal(a, b, equal_nan=True) else float("inf")
    return float(np.max(np.abs(a - b), initial=0.0) / (np.max(np.abs(a), initial=0.0) or 1.0))


def pair_difference(ra: dict, rb: dict, arrays: tuple[dict, dict]) -> dict[str, Any]:
    """How two rows of one (scene, method) differ: status, iterations, u, λ, active set."""
    diff = {"scene": ra["scene"], "method": ra["method"], "status": (ra["status"], rb["status"]),
            "iterations": (ra.get("iterations"), rb.get("iterations"))}
    for name in ("u", "force"):
        a, b = (arr.get(f"{name}|{ra['scene']}|{ra['method']}") for arr in arrays)
        diff[name] = relative(a, b, (ra.get(f"{name}_norm"), rb.get(f"{name}_norm")))
        if a is None and ra.get(f"{name}_hash") != rb.get(f"{name}_hash") and diff[name] == 0.0:
            diff[name] = ROUND_OFF  # equal norms, different values: not provably round-off
    diff["active"] = len(set(ra.get("active", [])) ^ set(rb.get("active", [])))
    diff["differs"] = (ra["status"] != rb["status"] or diff["active"] > 0
                       or any(isinstance(diff[n], str) or not diff[n] <= ROUND_OFF for n in ("u", "force")))
    return diff


def differences(a: Path, b: Path) -> tuple[list[dict], list[str], list[str]]:
    """Every pair of both records compared, and the pairs only A or only B has (per scene)."""
    (meta_a, arr_a), (meta_b, arr_b) = load(a), load(b)
    rows_a, rows_b = ({(r["scene"], r["method"]): r for r in m["rows"]} for m in (meta_a, meta_b))
    both = [pair_difference(rows_a[k], rows_b[k], (arr_a, arr_b)) for k in rows_a if k in rows_b]
    return both, only_in(rows_a, rows_b), only_in(rows_b, rows_a)


def only_in(rows: dict, other: dict) -> list[str]:
    """The pairs of ``rows`` that ``other`` lacks: a scene it lacks whole, else each method."""
    scenes, missing = {scene for scene, _ in other}, [k for k in rows if k not in other]
    return [*dict.fromkeys(f"{s} (every method)" if s not in scenes else f"{s} {m}" for s, m in missing)]


def compare_table(a: Path, b: Path) -> str:
    """Markdown: where each record comes from, a row per pair beyond round-off, pairs one lacks."""
    both, only_a, only_b = differences(a, b)
    beyond = [d for d in both if d["differs"]]
    lines = [f"- {side}: `{path.name}`: " + "; ".join(
        f"{k} {m[k]}" for k in ("commit", "tree", "date", "machine", "load", "load_after", "sets") if k in m)
             for side, path, m in (("A", a, load(a)[0]), ("B", b, load(b)[0]))]
    lines += ["", f"{len(both)} solves in both records: {len(both) - len(beyond)} agree to "
              f"{ROUND_OFF:g} relative (status, active set, u and λ), {len(beyond)} differ beyond it.", ""]
    if beyond:
        lines += ["| scene | method | status | iterations | u rel. diff | λ rel. diff | active changes |",
                  "|---|---|---|---|---:|---:|---:|"]
    for d in beyond:
        status, its = (x[0] if x[0] == x[1] else f"{x[0]} → {x[1]}" for x in (d["status"], d["iterations"]))
        lines.append(f"| {d['scene']} | {d['method']} | {status} | {its} | " + " | ".join(
            x if isinstance(x, str) else f"{x:.1e}" for x in (d["u"], d["force"])) + f" | {d['active']} |")
    lines += [f"\nOnly in {side} ({len(names)}): {', '.join(names)}." for side, names in
              (("A", only_a), ("B", only_b)) if names]
    return "\n".join(lines)


def time_one(scene: str, method: str | None, sets: dict[str, str], warm: bool) -> None:
    """Seconds (JSON on stdout) of one solve at the scene's defaults or of the user's QP: from before
    ``import signorini`` (cold) or after the small solve of the same scene and method (warm)."""
    start = time.perf_counter(), time.process_time()
    import signorini

    def solve(small: bool) -> Any:
        problem, params = problem_of(scene, sets, small)
        return signorini.solve(problem, *[m for m in (method,) if m], params=params)

    if scene != USERS_QP and scene not in signorini.scene_families():
        return print(json.dumps({"absent": True}))
    if warm:
        solve(small=True)
        start = time.perf_counter(), time.process_time()
    status = solve(small=False).status
    print(json.dumps({"wall": time.perf_counter() - start[0], "cpu": time.process_time() - start[1],
                      "status": status}))


def speed(old: Path, new: Path, rounds: int, sets: dict[str, str]) -> dict[str, Any]:
    """Each case warm and cold in a fresh process per tree, alternating (new first in odd rounds)."""
    runs: dict[tuple[str, str, str], list[dict]] = {}
    meta = {**machine(new), "old": f"{old} ({machine(old)['commit']})", "rounds": rounds, "sets": sets}
    cases = {f"{scene} {method or 'default'}": (scene, method) for scene, method in SPEED_CASES}
    missing: set[str] = set()
    for round_, (case, (scene, method)) in itertools.product(range(rounds), cases.items()):
        order = (("old", old), ("new", new))[::1 - 2 * (round_ % 2)]
        for (side, tree), kind in itertools.product(order, KINDS):
            command = [sys.executable, __file__, "_time", scene, method or "", f"--kind={kind}",
                       *[f"--set={k}={v}" for k, v in sets.items()]]
            env = {**os.environ, "PYTHONPATH": str(tree)}
            out = "" if case in missing else subprocess.run(command, env=env, capture_output=True,
                                                             text=True, check=True).stdout
            row = json.loads(out.splitlines()[-1]) if out else {"absent": True}
            missing |= {case} if row.get("absent") else set()  # a scene one tree lacks: not timed
            runs.setdefault((case, side, kind), []).append(row)
    meta["load_after"] = [round(x, 2) for x in os.getloadavg()]
    meta["runs"] = {" ".join(key): rows for key, rows in runs.items() if key[0] not in missing}
    meta["cases"] = [case for case in cases if case not in missing]
    return meta


def speed_table(meta: dict[str, Any]) -> str:
    """Per case and clock, the medians and their ratio new / old, and the range of one round's."""
    lines = ["| solve | timed | old s | new s | new / old | lowest–highest of one round |",
             "|---|---|---:|---:|---:|---:|"]
    for case, kind, clock in itertools.product(meta["cases"], KINDS, CLOCKS):
        old, new = ([r[clock] for r in meta["runs"][f"{case} {side} {kind}"]] for side in ("old", "new"))
        each, (o, n) = [n / o for o, n in zip(old, new)], map(statistics.median, (old, new))
        lines.append(f"| {case} | {kind}, {clock} | {o:.3f} | {n:.3f} | **{n / o:.2f}** | "
                     f"{min(each):.2f}–{max(each):.2f} |")
    return "\n".join(lines + ["", f"Medians of {meta['rounds']} interleaved rounds; old {meta['old']}, new "
                              f"{meta['tree']} ({meta['commit']}); {meta['machine']}; load average "
                              f"{meta['load'][0]:.1f} before, {meta['load_after'][0]:.1f} after."])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("command", choices=("record", "compare", "speed", "_time"))  # _time: of speed
    parser.add_argument("paths", nargs="*", help="compare: A B; speed: OLD_TREE NEW_TREE")
    parser.add_argument("--out", type=Path, help="record: FILE.npz|.json; compare: FILE.md; speed: FILE.json")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="a scene parameter, wherever a family takes it (mesher=relaxed)")
    parser.add_argument("--timeout", type=float, default=120.0, help="record: seconds a solve may take")
    parser.add_argument("--rounds", type=int, default=5, help="speed: interleaved rounds")
    parser.add_argument("--kind", choices=KINDS, default="cold", help="_time: after a small solve or not")
    args = parser.parse_args(argv)
    sets, paths = dict(s.split("=", 1) for s in args.set), [Path(p) for p in args.paths]
    if len(paths) != {"record": 0, "compare": 2, "speed": 2, "_time": 2}[args.command]:
        parser.error(f"{args.command} takes {'no paths' if args.command == 'record' else 'two paths'}")
    if args.command == "record":
        record(args.out or parser.error("record needs --out FILE.npz"), sets, args.timeout)
    elif args.command == "compare":
        table = compare_table(*paths)
        args.out.write_text(table + "\n") if args.out else print(table)
    elif args.command == "speed":
        meta = speed(paths[0].resolve(), paths[1].resolve(), args.rounds, sets)
        args.out.write_text(json.dumps(meta, indent=1) + "\n") if args.out else None
        print(speed_table(meta))
    else:
        time_one(args.paths[0], args.paths[1] or None, sets, args.kind == "warm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
