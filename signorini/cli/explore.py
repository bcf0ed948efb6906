"""``signorini explore``: serve the interactive lessons on this machine."""

from __future__ import annotations

import argparse
import importlib.util
import socket
import threading
import webbrowser

from signorini.errors import InputError

DESCRIPTION = """\
Serve four interactive lessons in a local web app (marimo): Uzawa on the bogie (the step
bound 2/lambda_max(W)), Hertz live (load, E, nu), Prices (the envelope theorem) and the
methods race. Every slider re-solves in the package; each lesson shows the answer's KKT
certificate. Nothing is fetched from the network. Ctrl-C stops the server."""

EPILOG = """\
examples:
  signorini explore                           serve on port 2718 and open a browser
  signorini explore --no-browser --port 8800  serve only (open http://127.0.0.1:8800 yourself)

exit codes:
  0  the server was stopped (Ctrl-C)
  2  bad input: a port out of range or in use, or marimo not installed"""

HOST = "127.0.0.1"


def free(port: int) -> bool:
    """Whether ``port`` on the loopback address can be bound now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        try:
            probe.bind((HOST, port))
        except OSError:
            return False
    return True


def _open_when_up(url: str, port: int, stop: threading.Event) -> None:
    """Open ``url`` in a browser once the server answers (at most a minute of waiting)."""
    for _ in range(600):
        if stop.wait(0.1):
            return
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            if probe.connect_ex((HOST, port)) == 0:
                webbrowser.open(url)
                return


def cmd_explore(args: argparse.Namespace) -> int:
    if not 1 <= args.port <= 65535:
        raise InputError(f"--port {args.port} is not a port: give one from 1 to 65535")
    if importlib.util.find_spec("marimo") is None or importlib.util.find_spec("anywidget") is None:
        raise InputError("the explorer needs marimo and anywidget: pip install 'signorini[explore]'")
    if not free(args.port):
        raise InputError(f"--port {args.port} is in use on {HOST}: give another with --port")
    import marimo  # per command: the web app's libraries start only here
    import uvicorn  # (marimo's own server)

    from signorini.output import explorer  # per command (start-up)

    server = marimo.create_asgi_app(quiet=True).with_app(path="", root=explorer.__file__).build()
    url = f"http://{HOST}:{args.port}"
    print(f"signorini explore: serving the lessons on {url} (Ctrl-C stops)", flush=True)
    stop = threading.Event()
    if not args.no_browser:
        threading.Thread(target=_open_when_up, args=(url, args.port, stop), daemon=True).start()
    try:
        uvicorn.run(server, host=HOST, port=args.port, log_level="warning")
    finally:
        stop.set()
    return 0


def add_parsers(sub) -> None:
    """Register ``explore``."""
    parser = sub.add_parser("explore", help="serve the interactive lessons in a local web app",
                            description=DESCRIPTION, epilog=EPILOG,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--port", type=int, default=2718, help="the port to serve on (default 2718)")
    parser.add_argument("--no-browser", action="store_true",
                        help="serve without opening a browser")
    parser.set_defaults(run=cmd_explore)
