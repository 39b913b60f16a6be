"""The ``asymslide`` command line.

``asymslide serve``  the web app, as ``make serve`` and the Docker image run it;
``asymslide sweep``  compute a stability atlas (Dask, stored in Zarr, resumable);
``asymslide info``   describe an atlas;
``asymslide export`` write an atlas as one NetCDF file;
``asymslide warmup`` compile the model's kernels into numba's cache (the launcher and the Docker build do).
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
from collections.abc import Callable, Sequence
from importlib import metadata
from pathlib import Path

from . import __version__

#: the engine's defaults (asymslide.atlas.plan.CHUNK_POINTS, asymslide.atlas.refinement.CHUNK_POINTS), without importing
#: them for --help
CHUNK_POINTS = 8192
ADAPTIVE_CHUNK_POINTS = 131072


#: exit codes besides 0 (done) and 2 (bad command line, as argparse)
EXIT_SCHEDULER = 3  # the scheduler address did not answer
EXIT_MISSING_EXTRA = 4  # the command needs an extra that is not installed (pip install 'asymslide[EXTRA]')
EXIT_INTERRUPTED = 130  # Ctrl-C: the chunks written so far are kept; run the same command again to resume

#: the extra each command needs besides the model (`pip install asymslide` installs only the model's dependencies)
COMMAND_EXTRAS = {"serve": "app", "sweep": "atlas", "info": "atlas", "export": "atlas"}
#: what each extra is, for the message
EXTRA_PURPOSE = {"app": "the web app", "atlas": "the atlas engine"}


def _serve(args: argparse.Namespace) -> int:
    """Run the server until it exits or a stop signal arrives. SIGTERM (docker stop, systemctl stop) is the normal
    way to stop a server: once every server process has stopped, that is exit 0, not 128 + 15."""
    from .serve import panel_command, run, warm_kernels

    origins = args.allow_websocket_origin or [f"localhost:{args.port}", f"127.0.0.1:{args.port}"]
    cmd = panel_command(port=args.port, address=args.address, origins=origins, num_procs=args.num_procs,
                        liveness=args.liveness, extra=args.panel_args)
    env = dict(os.environ)
    if args.atlas_dir:
        env["ASYMSLIDE_ATLAS_DIR"] = str(Path(args.atlas_dir).expanduser().resolve())
    # kernels compiled before the server accepts a page: by each server process itself (--setup), and with several
    # processes once before, by the launcher, so that they load the cache instead of compiling it side by side
    stopped = warm_kernels(env) if args.num_procs > 1 else None
    code = stopped if stopped is not None else run(cmd, env=env)
    return 0 if code == 128 + signal.SIGTERM else code


_REQUIREMENT = re.compile(r"^\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*(?:\[([^\]]*)\])?[^;]*(?:;(.*))?$")
_EXTRA_MARKER = re.compile(r"""extra\s*==\s*["']([^"']+)["']""")


def missing_requirements(extra: str, dist: str = "asymslide") -> list[str] | None:
    """The distributions `dist[extra]` requires (through nested extras too) that are not installed, from the
    installed metadata; None if `dist` itself is not installed (a source tree on sys.path)."""
    missing: list[str] = []
    seen: set[tuple[str, str]] = set()

    def walk(name: str, wanted: str) -> bool:
        if (name.lower(), wanted) in seen:
            return True
        seen.add((name.lower(), wanted))
        try:
            requires = metadata.requires(name) or []
        except metadata.PackageNotFoundError:
            return False
        for line in requires:
            match = _REQUIREMENT.match(line)
            if match is None:
                continue
            req, extras, marker = match.groups()
            extra_of = _EXTRA_MARKER.search(marker or "")
            if extra_of is None or extra_of.group(1) != wanted:
                continue  # the base requirements are installed with the distribution; other extras are not asked for
            nested = [e.strip() for e in (extras or "").split(",") if e.strip()]
            found = all([walk(req, e) for e in nested]) if nested else _installed(req)
            if not found and req not in missing:
                missing.append(req)
        return True

    return missing if walk(dist, extra) else None


def _installed(name: str) -> bool:
    try:
        metadata.distribution(name)
    except metadata.PackageNotFoundError:
        return False
    return True


def _missing_extra_message(command: str, extra: str, missing: Sequence[str]) -> str:
    return (f"'asymslide {command}' needs {EXTRA_PURPOSE[extra]}'s dependencies, which are not installed "
            f"(missing: {', '.join(missing)}). Install them with: pip install 'asymslide[{extra}]'")


def _fail(message: str, code: int = 2) -> int:
    print(f"asymslide: error: {message}", file=sys.stderr)
    return code


def _adaptive_spec(args: argparse.Namespace) -> tuple[list[str], object]:
    """The axis specs (rounded to an adaptive grid with --adaptive, saying so on stderr) and the AdaptiveSpec (None:
    a dense sweep); SweepError for adaptive options without --adaptive."""
    from asymslide.atlas.plan import SweepError

    specs, adaptive = list(args.axis), None
    if args.adaptive:
        from asymslide.atlas.refinement import AdaptiveSpec

        specs, levels, notes = _adaptive_axis_specs(specs, args.levels)
        for note in notes:
            print(f"asymslide: note: {note}", file=sys.stderr)
        adaptive = AdaptiveSpec(levels=levels, margin=0 if args.margin is None else args.margin, guard=args.guard,
                                follow=not args.no_follow, verdict=args.verdict)
    elif args.levels is not None or args.margin is not None or args.guard or args.no_follow or args.verdict:
        raise SweepError("--levels, --margin, --guard, --no-follow and --verdict belong to an adaptive sweep: add "
                         "--adaptive")
    return specs, adaptive


def _sweep_settings(args: argparse.Namespace, specs: Sequence[str]) -> tuple[dict, dict]:
    """The axes (from `specs`) and the other settings of ``asymslide sweep``'s arguments (SweepError or ValueError if
    bad)."""
    from asymslide.atlas.plan import CountSpec, SlidingSpec, SweepError, parse_axis, parse_fixed, parse_number

    axes = dict(parse_axis(a) for a in specs)
    if len(axes) != len(args.axis):
        raise SweepError("an axis is given twice")
    fixed = dict(parse_fixed(f) for f in args.fixed)
    _, kh = parse_axis(f"kH={args.kH}")
    gamma_range = tuple(float(x) for x in args.gamma_range.split(":")) if args.gamma_range else None
    if gamma_range is not None and len(gamma_range) != 2:
        raise SweepError(f"--gamma-range must be lo:hi; got {args.gamma_range!r}")
    count = None
    if args.count:
        window = tuple(float(x) for x in args.count.split(","))
        if len(window) != 3:
            raise SweepError(f"--count must be re_max,im_min,im_max; got {args.count!r}")
        count = CountSpec(tuple(parse_axis(f"kH={args.count_kH}")[1]), window)  # type: ignore[arg-type]
    sliding = None
    if args.sliding or args.verdict == "sliding" or args.sliding_thresholds:  # these need the sliding verdict
        sliding = SlidingSpec(tuple(parse_axis(f"kH={args.sliding_kH}")[1]), parse_number("--floor", args.floor),
                              args.sliding_thresholds)
    settings = dict(fixed=fixed, kH=kh, rtol=args.rtol, growth=not args.no_growth, gamma_c=not args.no_gamma_c,
                    gamma_range=gamma_range, count=count, chunk_points=args.chunk_points, sliding=sliding)
    return axes, settings


def _adaptive_axis_specs(specs: Sequence[str], levels: int | None) -> tuple[list[str], int, list[str]]:
    """Axis specs whose lo:hi:n ranges are rounded up to m·2^levels + 1 points (levels None: the engine's default
    for the requested sizes), the levels, and a note per rounded axis (lists of values are left to make_plan, which
    refuses a size that does not fit)."""
    from asymslide.atlas.plan import parse_axis
    from asymslide.atlas.refinement import adaptive_size, default_levels

    sizes = [parse_axis(spec)[1].size for spec in specs]
    if levels is None:
        levels = default_levels(sizes)
    out, notes = [], []
    for spec, n in zip(specs, sizes, strict=True):
        name, _, values = spec.partition("=")
        parts = values.split(":")
        want = adaptive_size(n, levels)
        if len(parts) in (3, 4) and want != n:
            parts[2] = str(want)
            spec = f"{name}={':'.join(parts)}"
            notes.append(f"axis {name.strip()}: {n} points rounded up to {want} = {(want - 1) // 2**levels}·2^{levels} "
                         f"+ 1 (an adaptive grid nests the grids of stride 2^{levels} .. 1)")
        out.append(spec)
    return out, levels, notes


def _sweep(args: argparse.Namespace) -> int:
    from asymslide.atlas.executor import CONNECT_TIMEOUT
    from asymslide.atlas.plan import SweepError, make_plan
    from asymslide.atlas.sweep import run

    try:
        specs, adaptive = _adaptive_spec(args)
        axes, settings = _sweep_settings(args, specs)
        settings["adaptive"] = adaptive
        plan = make_plan(axes, **settings)
    except (SweepError, ValueError) as exc:
        return _fail(str(exc))
    client = None
    if args.scheduler:
        try:
            client = _connect(args.scheduler)
        except (OSError, TimeoutError, ValueError) as exc:
            return _fail(f"the scheduler at {args.scheduler} did not answer within {CONNECT_TIMEOUT} s "
                         f"({type(exc).__name__}: {exc})", EXIT_SCHEDULER)
    bars, start = _progress_bars(plan, args.quiet)
    command = " ".join(["asymslide", *sys.argv[1:]]) if sys.argv and sys.argv[0].endswith("asymslide") else None
    try:
        ds = run(plan, store=args.out, client=client, workers=args.workers,
                 progress=lambda kind, n: bars[kind].update(n), start=start, command=command)
    except SweepError as exc:
        return _fail(str(exc))
    except KeyboardInterrupt:
        print(f"\ninterrupted: the chunks written so far are in {args.out}; run the same command to resume",
              file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        for bar in bars.values():
            bar.close()
        if client is not None:
            client.close()
    print(f"atlas written to {args.out}")
    if plan.adaptive is not None:
        _print_adaptive(ds)
    return 0


def _progress_bars(plan, quiet: bool) -> tuple[dict, Callable[[str, int], None]]:
    """A tqdm bar per task kind (an adaptive sweep's growth: one per level, made by `start` as each level starts)."""
    from tqdm import tqdm

    from asymslide.atlas.plan import plan_points

    bars: dict = {}

    def start(kind: str, n: int) -> None:
        if kind in bars:  # an adaptive level's follow round: its points join the level's bar
            bars[kind].total += n
            bars[kind].refresh()
            return
        bars[kind] = tqdm(total=n, desc=f"{kind:8s}", unit="pt", unit_scale=True, dynamic_ncols=True,
                          position=len(bars), disable=quiet)

    for kind, n in plan_points(plan).items():
        if not (kind == "growth" and plan.adaptive is not None):
            start(kind, n)
    return bars, start


def _connect(address: str):
    """A ``distributed.Client`` of the scheduler at `address` (OSError, TimeoutError or ValueError if it does not
    answer within CONNECT_TIMEOUT)."""
    from distributed import Client

    from asymslide.atlas.executor import CONNECT_TIMEOUT

    return Client(address, timeout=CONNECT_TIMEOUT)


def _print_adaptive(ds) -> None:
    """The evaluated fraction of an adaptive sweep, per level."""
    from asymslide.atlas.summary import adaptive_lines

    for line in adaptive_lines(ds.attrs["adaptive"], ds["computed"].values):
        print(line)


def _info(args: argparse.Namespace) -> int:
    from asymslide.atlas.summary import iter_summary

    try:
        for line in iter_summary(args.store):
            print(line, flush=True)
    except BrokenPipeError:  # the reader stopped (asymslide info STORE | head): not the atlas's fault
        _quiet_stdout()
        return 1
    except (OSError, ValueError, KeyError) as exc:
        return _fail(f"{args.store} is not a readable atlas ({type(exc).__name__}: {exc})")
    return 0


def _quiet_stdout() -> None:
    """Point stdout at /dev/null so that Python's flush at exit does not fail again on the closed pipe (the recipe of
    the signal module's documentation, "Note on SIGPIPE")."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())


def _export(args: argparse.Namespace) -> int:
    from asymslide.atlas.sweep import export_netcdf

    try:
        out = export_netcdf(args.store, args.netcdf)
    except (OSError, ValueError, KeyError) as exc:
        return _fail(f"could not export {args.store} ({type(exc).__name__}: {exc})")
    print(f"written {out}")
    return 0


def _warmup(args: argparse.Namespace) -> int:
    from .warmup import compile_kernels

    compile_kernels(log=print)
    return 0


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
    serve.add_argument("--atlas-dir", metavar="DIR", help="the directory the Atlas tab reads atlases from (and "
                                                          "computes the default atlas into); default "
                                                          "$ASYMSLIDE_ATLAS_DIR or ~/.cache/asymslide/atlases")
    serve.add_argument("panel_args", nargs="*", metavar="-- PANEL_ARGS", help="passed to panel serve")
    serve.set_defaults(func=_serve)

    sw = sub.add_parser("sweep", help="compute a stability atlas over a grid of parameters (resumable)",
                        description="Max growth of the Rayleigh branch (and the threshold gamma_c) over a grid of "
                                    "parameters, computed with Dask and written chunk by chunk to a Zarr store. "
                                    "Running the same command again resumes an interrupted sweep.")
    sw.add_argument("--axis", action="append", required=True, metavar="NAME=LO:HI:N[:log]",
                    help="a grid axis: gamma, f, beta, eta, Delta or xi; lo:hi:n points, linear or :log (eta: log "
                         "unless :lin), or an explicit list v1,v2,...; repeatable")
    sw.add_argument("--fixed", action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter held fixed (eta=inf allowed); the others take the paper's values gamma=3, "
                         "f=0.9, beta=0.3, eta=inf, Delta=1, xi=0 (model.PARAMETERS)")
    sw.add_argument("--out", required=True, help="the Zarr store (a directory) to write or resume")
    sw.add_argument("--kH", default="1e-3:1e3:97:log", metavar="LO:HI:N[:log]",
                    help="the kH grid the growth is bracketed on (default 1e-3:1e3:97:log)")
    sw.add_argument("--rtol", type=float, default=None, help="relative accuracy of the roots (default: full)")
    sw.add_argument("--no-growth", action="store_true", help="skip the growth variables (e.g. gamma_c only)")
    sw.add_argument("--no-gamma-c", action="store_true", help="skip the threshold gamma_c over the other axes")
    sw.add_argument("--gamma-range", metavar="LO:HI", help="where gamma_c is searched (default: the gamma axis' "
                                                           "range, or 1e-2:1e3)")
    sw.add_argument("--count", metavar="RE_MAX,IM_MIN,IM_MAX",
                    help="also count every unstable root (any branch) in this window")
    sw.add_argument("--count-kH", default="0.1:10:5:log", metavar="LO:HI:N[:log]",
                    help="kH grid of the count (default 0.1:10:5:log)")
    sw.add_argument("--sliding", action="store_true",
                    help="also the sliding verdict over every branch (growth_all, verdict_all, ...; about 10 ms a "
                    "point at eta = inf, 0.1 s at finite eta; an adaptive sweep then refines it: --verdict)")
    sw.add_argument("--sliding-thresholds", action="store_true",
                    help="also the threshold of sliding in gamma over every branch (gamma_c_all and its crossings, "
                    "with gamma_c; implies --sliding; ~0.5 s a point of the other axes at eta = inf, ~10 s at finite "
                    "eta)")
    sw.add_argument("--sliding-kH", default="1e-2:1e2:17:log", metavar="LO:HI:N[:log]",
                    help="kH grid of the sliding verdict (default 1e-2:1e2:17:log, the model's)")
    sw.add_argument("--floor", default="1e-6", metavar="GROWTH",
                    help="growth floor of the sliding verdict: roots with Im z below it are not searched "
                    "(default 1e-6)")
    sw.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler, e.g. tcp://HOST:8786 (default: "
                                                           "threads on this machine)")
    sw.add_argument("--workers", type=int, default=None, help="threads on this machine (default: one per core)")
    sw.add_argument("--chunk-points", type=int, default=None,
                    help=f"grid points per growth chunk (default {CHUNK_POINTS}; adaptive {ADAPTIVE_CHUNK_POINTS})")
    sw.add_argument("--adaptive", action="store_true",
                    help="compute the growth only where the verdict can change: a coarse grid, then the cells whose "
                         "corners differ in verdict refined level by level, following the boundary out of them; "
                         "axes of lo:hi:n points are rounded up to m*2^levels + 1 (see docs/guide/atlases.md)")
    sw.add_argument("--levels", type=int, default=None, metavar="L",
                    help="adaptive: refinement levels, the coarse grid has stride 2^L (default: about 9 points on "
                         "the longest axis)")
    sw.add_argument("--margin", type=int, default=None, metavar="M",
                    help="adaptive: rings of cells also refined around each cell whose corners differ (default 0: "
                         "the boundary is followed instead, see --no-follow)")
    sw.add_argument("--no-follow", action="store_true",
                    help="adaptive: do not follow the boundary out of the refined cells (each level's cells whose "
                         "evaluated corners differ get their other corners evaluated, until none is left); pair it "
                         "with --margin 1 for a ring of cells around the refined ones instead")
    sw.add_argument("--verdict", choices=("sliding", "rayleigh"), default=None,
                    help="adaptive: the verdict refined: sliding (every branch above --floor, and the Rayleigh "
                         "branch's: a cell is refined where either changes; implies --sliding) or rayleigh (the "
                         "Rayleigh branch's alone); default: sliding with --sliding, else rayleigh")
    sw.add_argument("--guard", type=float, nargs="?", const=1.0, default=0.0, metavar="FACTOR",
                    help="adaptive: also refine nearly neutral cells, where min abs(growth) over the corners is below "
                         "FACTOR (default 1) times the curvature estimate (finds islands inside a cell; costs more "
                         "points)")
    sw.add_argument("--quiet", action="store_true", help="no progress bars")
    sw.set_defaults(func=_sweep)

    info = sub.add_parser("info", help="describe an atlas")
    info.add_argument("store")
    info.set_defaults(func=_info)

    export = sub.add_parser("export", help="write an atlas as one NetCDF file")
    export.add_argument("store")
    export.add_argument("netcdf", help="the .nc file to write")
    export.set_defaults(func=_export)

    warm = sub.add_parser("warmup", help="compile the model's kernels into numba's cache (NUMBA_CACHE_DIR)")
    warm.set_defaults(func=_warmup)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command == "serve" and args.num_procs < 1:
        parser.error(f"--num-procs must be >= 1; got {args.num_procs}")
    extra = COMMAND_EXTRAS.get(args.command)
    if extra is not None and (missing := missing_requirements(extra)):
        return _fail(_missing_extra_message(args.command, extra, missing), EXIT_MISSING_EXTRA)
    try:
        return args.func(args)
    except ModuleNotFoundError as exc:  # a source tree that was never installed: no metadata to check beforehand
        root = (exc.name or "").partition(".")[0]
        if extra is None or not root or root == "asymslide":
            raise
        return _fail(_missing_extra_message(args.command, extra, [root]), EXIT_MISSING_EXTRA)


if __name__ == "__main__":
    sys.exit(main())
