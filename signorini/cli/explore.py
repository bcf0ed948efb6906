"""``signorini explore``: serve the interactive lessons on this machine."""

from __future__ import annotations

import argparse
import importlib.util
import os
import socket
import subprocess
import sys
from pathlib import Path

from signorini.cli.common import add_command
from signorini.errors import InputError

DESCRIPTION = """\
Serve four interactive lessons in a local web app (marimo): Uzawa on the bogie (the step
bound 2/lambda_max(W)), Hertz live (load, E, nu), Prices (the envelope theorem) and the
methods race. Every slider re-solves in the package; each lesson shows the answer's KKT
certificate. Nothing is fetched from the network. Ctrl-C stops the server."""

HOST = "127.0.0.1"
#: seconds the server has to close its sessions once asked to stop
GRACE = 10


def free(port: int) -> bool:
    """Whether ``port`` on the loopback address can be bound now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        try:
            probe.bind((HOST, port))
        except OSError:
            return False
    return True


def server_command(port: int, open_browser: bool) -> list[str]:
    """``marimo run`` of the lessons' app on ``HOST:port`` (headless unless ``open_browser``)."""
    app = Path(__file__).resolve().parents[1] / "output" / "explorer.py"
    return ([sys.executable, "-m", "marimo", "--quiet", "--yes", "run", str(app), "--host", HOST,
             "--port", str(port)] + ([] if open_browser else ["--headless"]))


def cmd_explore(args: argparse.Namespace) -> int:
    if not 1 <= args.port <= 65535:
        raise InputError(f"--port {args.port} is not a port: give one from 1 to 65535")
    if importlib.util.find_spec("marimo") is None or importlib.util.find_spec("anywidget") is None:
        raise InputError("the explorer needs marimo and anywidget: pip install 'signorini[explore]'")
    if not free(args.port):
        raise InputError(f"--port {args.port} is in use on {HOST}: give another with --port")
    # marimo's own server, in a child that imports this same package and never checks for updates
    package_root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "MARIMO_SKIP_UPDATE_CHECK": "1",
           "PYTHONPATH": os.pathsep.join(filter(None, [package_root, os.environ.get("PYTHONPATH")]))}
    print(f"signorini explore: serving the lessons on http://{HOST}:{args.port} (Ctrl-C stops)",
          flush=True)
    with subprocess.Popen(server_command(args.port, not args.no_browser), env=env) as server:
        try:
            return server.wait()
        finally:  # stopped by a signal: the server closes its sessions, or is ended
            if server.poll() is None:
                server.terminate()
                try:
                    server.wait(timeout=GRACE)
                except subprocess.TimeoutExpired:
                    server.kill()
                    server.wait()


def add_parsers(sub) -> None:
    """Register ``explore``."""
    parser = add_command(
        sub, "explore", "serve the interactive lessons in a local web app", DESCRIPTION,
        ["signorini explore                           # serve on port 2718, open a browser",
         "signorini explore --no-browser --port 8800  # serve only: open http://127.0.0.1:8800"],
        {0: "the server ended by itself", 2: "bad input: a port out of range or in use, or "
         "marimo not installed"})
    parser.add_argument("--port", type=int, default=2718, help="the port to serve on (default 2718)")
    parser.add_argument("--no-browser", action="store_true",
                        help="serve without opening a browser")
    parser.set_defaults(run=cmd_explore)


__all__ = ["free", "server_command", "cmd_explore", "add_parsers"]
