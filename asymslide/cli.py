"""The ``asymslide`` command line: ``asymslide serve`` (the web app, as ``make serve`` and the Docker image run it)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from . import __version__


def _serve(args: argparse.Namespace) -> int:
    from .serve import panel_command, run

    origins = args.allow_websocket_origin or [f"localhost:{args.port}", f"127.0.0.1:{args.port}"]
    cmd = panel_command(port=args.port, address=args.address, origins=origins, num_procs=args.num_procs,
                        liveness=args.liveness, extra=args.panel_args)
    return run(cmd)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="asymslide", description=__doc__)
    parser.add_argument("--version", action="version", version=f"asymslide {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    serve = sub.add_parser("serve", help="serve the web app (stops completely, workers included, on SIGTERM/Ctrl-C)",
                           description="Serve the web app with panel serve; extra arguments after -- go to panel "
                                       "serve unchanged.")
    serve.add_argument("--port", type=int, default=5006, help="port (default 5006)")
    serve.add_argument("--address", default="0.0.0.0", help="address to listen on (default 0.0.0.0)")
    serve.add_argument("--allow-websocket-origin", action="append", metavar="HOST[:PORT]",
                       help="host whose pages may open the app's websocket; repeatable "
                            "(default: localhost:PORT and 127.0.0.1:PORT)")
    serve.add_argument("--num-procs", type=int, default=1, help="server processes (at most one per core; default 1)")
    serve.add_argument("--liveness", action="store_true", help="answer health checks at /liveness")
    serve.add_argument("panel_args", nargs="*", metavar="-- PANEL_ARGS", help="passed to panel serve")
    serve.set_defaults(func=_serve)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "serve" and args.num_procs < 1:
        parser.error(f"--num-procs must be >= 1; got {args.num_procs}")
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
