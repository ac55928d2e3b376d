"""The ``crisgeo`` command line.

Exit status: 0 success; 1 failure (a run failed, the store is unusable); 2 bad input (one line on stderr:
arguments, configuration, data); 75 another instance holds the state directory (try again later). ``crisgeo
status`` follows the Nagios plugin convention instead: 0 OK, 1 WARNING (a warning alert fires), 2 CRITICAL
(a critical alert fires or the last run of a satellite failed), 3 UNKNOWN (no usable configuration or store).
The configuration is ``--config``, else ``$CRISGEO_CONFIG``, else ``/etc/crisgeo/monitor.yaml``.

Why one module of ~1000 lines: each command is its arguments beside the short function that parses, calls
and prints (the work is in the modules it calls); one parser gives ``crisgeo --help``, ``docs/cli.md`` and
the one place errors become exit statuses (:func:`main`).
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO, TypeVar

from monitor.cli.render import result_text
from monitor.config.model import AssessmentConfig, Config, FingerprintConfig
from monitor.core.constants import N_FOV
from monitor.core.errors import DataError
from monitor.core.satellites import SATELLITES
from monitor.core.vocabulary import Cost, Kernel, Rule
from monitor.instrument.footprint import SHAPES as FOOTPRINTS
from monitor.service import allocator, logs
from monitor.simulate import LAYOUTS
from monitor.simulate.orbit import PASSES
from monitor.version import __version__

if TYPE_CHECKING:  # the commands import what they run when they run it: crisgeo starts fast
    from monitor.core.changes import Change
    from monitor.geometry.instrument import EngineeringPacket
    from monitor.instrument.footprint import RadialResponse
    from monitor.mapping.fingerprint import DayPrint, EpMatch
    from monitor.mapping.residuals import OwnResiduals, ResidualTable
    from monitor.service.store.sqlite import Store

Handler = Callable[[argparse.Namespace], int]  # a subcommand: its parsed arguments in, its exit status out
SectionT = TypeVar("SectionT", AssessmentConfig, FingerprintConfig)  # a section that commands take as options

# the defaults of the assessment keys, for the commands that take them as flags
ASSESSMENT = AssessmentConfig()  # the defaults of the options that mirror configuration keys
FINGERPRINT = FingerprintConfig()

EXIT_OK, EXIT_FAIL, EXIT_BAD_INPUT = 0, 1, 2
EXIT_ALREADY_RUNNING = 75  # sysexits EX_TEMPFAIL
DEFAULT_CONFIG = "/etc/crisgeo/monitor.yaml"


class BadInput(Exception):
    """An error in what the user gave; reported as one line, exit status 2."""


def _iso(text: str) -> dt.datetime:
    try:
        when = dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an ISO 8601 time: {text!r}") from None
    return when if when.tzinfo else when.replace(tzinfo=dt.timezone.utc)


def _until(text: str) -> dt.datetime:
    """An end: ISO 8601 (UTC unless it says), or a duration from now, ``12h`` or ``7d``."""
    m = re.fullmatch(r"(\d{1,4})([hd])", text.strip())
    if m:
        hours = int(m[1]) * (24 if m[2] == "d" else 1)
        return dt.datetime.now(dt.timezone.utc).replace(microsecond=0) + dt.timedelta(hours=hours)
    try:
        return _iso(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"not an ISO 8601 time nor a duration (12h, 7d): {text!r}") from None


def _day(text: str) -> dt.date:
    try:
        return dt.date.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a date (YYYY-MM-DD): {text!r}") from None


def _whole(least: int) -> Callable[[str], int]:
    """The argparse type of a whole number of at least *least* (a count of granules or processes, a seed)."""

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
        if n < least:
            raise argparse.ArgumentTypeError(f"{n}: at least {least}")
        return n

    return parse


def _longitude(text: str) -> float:
    """A longitude in degrees, -180..180."""
    try:
        lon = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not -180.0 <= lon <= 180.0:  # NaN fails too
        raise argparse.ArgumentTypeError(f"{text}: not a longitude within -180..180 deg")
    return lon


def _options(model: type[SectionT], flags: str, **values: Any) -> SectionT:
    """The options of a command that are keys of a configuration section (*model*), checked by the same
    model as the file: a problem is bad input naming the *flags* and the key."""
    from monitor.config.file import section_of
    from monitor.config.model import ConfigError

    name = next(k for k, f in Config.model_fields.items() if f.annotation is model)
    try:
        section = section_of(name, **values)
    except ConfigError as exc:
        raise BadInput(f"{flags}: {exc}") from None
    assert isinstance(section, model)
    return section


def arg(*names: str, **options: Any) -> tuple[tuple[str, ...], dict[str, Any]]:
    """One argument of a subcommand: the add_argument call, as data."""
    return names, options


CONFIG = arg("--config", help=f"configuration file (default: $CRISGEO_CONFIG, then {DEFAULT_CONFIG})")
# the options that are keys of the assessment section (checked by its model, :func:`_options`)
KERNEL = arg(
    "--kernel",
    choices=tuple(k.value for k in Kernel),
    default=ASSESSMENT.kernel.value,
    help="FOV weighting: the top-hat cone or the CrIS spatial response (assessment.kernel)",
)
COST = arg(
    "--cost",
    choices=tuple(c.value for c in Cost),
    default=ASSESSMENT.cost.value,
    help="stdev (the paper's) or regression (unmoved by a CrIS-VIIRS gain or bias) (assessment.cost)",
)
WORKERS = arg(
    "--workers",
    type=int,
    default=ASSESSMENT.workers,
    help=f"threads of the compiled kernels (default {ASSESSMENT.workers}, assessment.workers)",
)
RESIDUAL_ARGS = (
    arg("--residuals", help="per-FOR LOS residual table (crisgeo fingerprint --write-residuals)"),
    arg(
        "--own-residuals",
        metavar="EP_IN_FORCE",
        help="learn each granule's residual from itself, against the EP it was made with",
    ),
)
RULES = tuple(r.value for r in Rule)  # as strings: argparse prints its choices' repr
# name -> (handler, help, arguments), in the order of ``crisgeo --help``
COMMANDS: dict[str, tuple[Handler, str, tuple]] = {}


def command(
    name: str, help: str, *arguments: tuple[tuple[str, ...], dict[str, Any]]
) -> Callable[[Handler], Handler]:
    """Register the decorated handler as subcommand *name* with its *arguments* (:func:`arg`)."""

    def register(handler: Handler) -> Handler:
        COMMANDS[name] = (handler, help, arguments)
        return handler

    return register


@command(
    "simulate",
    "write simulated CrIS/VIIRS granules with an injected LOS error",
    arg("--out", required=True, help="output directory"),
    arg("--satellite", choices=tuple(SATELLITES), default="j01"),
    arg(
        "--granules", type=_whole(1), default=14, help="consecutive CrIS granules (default 14, as the paper)"
    ),
    arg("--profile", default="paper", help="paper, random, zero, or a JSON/YAML profile file"),
    arg("--seed", type=_whole(0), default=0),
    arg("--start", type=_iso, default=None, help="UTC start of the first granule (ISO 8601)"),
    arg("--true-ep", help="EP file (XML or YAML) the radiances are made with (with --ground-ep)"),
    arg("--ground-ep", help="EP file the GEO files are made with (the ground processing's EP)"),
    arg("--terrain", action="store_true", help="1-4 km ranges and plateaus over 40 %% land"),
    arg(
        "--pass",
        dest="orbit_pass",
        choices=sorted(PASSES),
        help="start at this pass of the satellite's orbit after --start (day: ascending tropics, "
        "night: descending, arctic/antarctic: 60-81 deg); default an ascending tropical pass",
    ),
    arg("--pass-lon", type=_longitude, help="with --pass: the pass nearest this longitude, deg (e.g. 180)"),
    arg(
        "--complete",
        action="store_true",
        help="every dataset of the real products, real size (GITCO ~325 MB uncompressed)",
    ),
    arg(
        "--layout",
        choices=LAYOUTS,
        help="HDF5 layout of every dataset (default: CrIS gzip, VIIRS contiguous)",
    ),
    arg(
        "--footprint",
        nargs="+",
        choices=tuple(FOOTPRINTS),
        metavar="SHAPE",
        help="the CrIS FOV's spatial response, one of " + ", ".join(FOOTPRINTS) + ": one shape for all FOVs, "
        "or nine (FOV 1..9); default the paper's top-hat cone",
    ),
)
def cmd_simulate(args: argparse.Namespace) -> int:
    """crisgeo simulate: write a simulated case."""
    from monitor.simulate.case import DEFAULT_START, SimulationSpec, simulate_case

    where = dict(
        terrain=args.terrain,
        orbit_pass=args.orbit_pass,
        pass_lon_deg=args.pass_lon,
        complete=args.complete,
        layout=args.layout,
        cris_response=_footprint(args.footprint),
    )
    if (args.true_ep is None) != (args.ground_ep is None):
        raise BadInput("--true-ep and --ground-ep go together")
    spec = None
    if args.true_ep:
        spec = SimulationSpec(
            satellite=args.satellite,
            granules=args.granules,
            seed=args.seed,
            start=args.start or DEFAULT_START,
            profile="ep",
            true_ep=_ep(args.true_ep),
            ground_ep=_ep(args.ground_ep),
            **where,
        )
    truth = simulate_case(
        args.out,
        satellite=args.satellite,
        granules=args.granules,
        profile=args.profile,
        seed=args.seed,
        start=args.start,
        spec=spec,
        **where,
    )
    error = f"EP {args.true_ep} over {args.ground_ep}" if args.true_ep else f"profile {args.profile}"
    print(
        f"wrote {len(truth['files'])} files and truth.json to {args.out} "
        f"({args.satellite}, {args.granules} CrIS granules, {error}, seed {args.seed})"
    )
    return EXIT_OK


def _footprint(names: Sequence[str] | None) -> RadialResponse | tuple[RadialResponse, ...] | None:
    """The spatial response of --footprint: None (the top-hat cone), one shape, or one per FOV."""
    from monitor.instrument.footprint import shape

    if not names:
        return None
    if len(names) not in (1, N_FOV):
        raise BadInput(f"--footprint takes one shape or {N_FOV} (FOV 1..{N_FOV}), not {len(names)}")
    return shape(names[0]) if len(names) == 1 else tuple(shape(n) for n in names)


def _ep(path: str | os.PathLike[str], satellite: str | None = None) -> EngineeringPacket:
    from monitor.sdr.engpkt import load_ep

    return load_ep(path, satellite)


def _residuals(args: argparse.Namespace) -> ResidualTable | OwnResiduals | None:
    """The residual table of --residuals FILE, or each granule's own against --own-residuals EP."""
    from monitor.mapping.residuals import OwnResiduals, ResidualError, load

    if args.residuals and args.own_residuals:
        raise BadInput("--residuals and --own-residuals exclude each other")
    if args.own_residuals:
        return OwnResiduals(_ep(args.own_residuals))
    if args.residuals is None:
        return None
    try:
        return load(args.residuals)
    except ResidualError as exc:
        raise BadInput(str(exc)) from None


@command(
    "optimize",
    "new scene-mirror angles (EP) from an assessment result (paper section 4)",
    arg("result", help="assessment result JSON (crisgeo assess --out)"),
    arg("--ep", required=True, help="the EP in force when the assessed data were made (XML or YAML)"),
    arg("--out", required=True, help="the proposed EP, in the format of --ep"),
    arg("--table-json", help="also write the old/new angle table as JSON here"),
)
def cmd_optimize(args: argparse.Namespace) -> int:
    """crisgeo optimize: new scene-mirror angles from an assessment."""
    import json

    from monitor.core.result import AssessmentResult
    from monitor.mapping.optimize import optimize
    from monitor.sdr.engpkt import save_ep

    try:
        result = AssessmentResult.from_json(Path(args.result).read_text())
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise BadInput(f"{args.result}: not an assessment result ({exc})") from None
    ep = _ep(args.ep)
    opt = optimize(result, ep, source=str(args.result))
    print(
        f"EP {ep.version} ({ep.satellite}) corrected by {args.result} ({result.start} .. {result.end}, "
        f"{len(result.granules)} granules)"
    )
    print(opt.table())
    save_ep(opt.ep, args.out, like=args.ep)
    print(f"wrote {args.out}")
    if args.table_json:
        Path(args.table_json).write_text(json.dumps([r.to_dict() for r in opt.rows], indent=1))
    return EXIT_OK


@command(
    "regeolocate",
    "write copies of CrIS GEO files geolocated with another EP",
    arg("files", nargs="+"),
    arg("--ep", required=True),
    arg("--out", required=True, help="output directory (never the input's)"),
    *RESIDUAL_ARGS,
)
def cmd_regeolocate(args: argparse.Namespace) -> int:
    """crisgeo regeolocate: GEO copies geolocated with another EP."""
    from monitor.mapping.regeolocate import regeolocate_file

    ep = _ep(args.ep)
    residuals = _residuals(args)
    failed = 0
    for path in args.files:
        try:
            out = regeolocate_file(ep, path, args.out, residuals)
            print(f"wrote {out}")
        except (DataError, OSError) as exc:
            failed += 1
            print(f"skipped {path}: {exc}", file=sys.stderr)
    if failed == len(args.files):
        raise BadInput("no file could be regeolocated")
    return EXIT_FAIL if failed else EXIT_OK


@command(
    "geolocate",
    "compare an EP's geolocation with CrIS GEO files' own, per FOR",
    arg("files", nargs="+"),
    arg("--ep", required=True),
    arg("--json", action="store_true"),
    *RESIDUAL_ARGS,
)
def cmd_geolocate(args: argparse.Namespace) -> int:
    """crisgeo geolocate: an EP's geolocation against the files' own, per FOR."""
    import json

    from monitor.mapping.regeolocate import compare_with_files

    ep = _ep(args.ep)
    rows = compare_with_files(ep, args.files, _residuals(args))
    if args.json:
        print(
            json.dumps(
                {"ep": ep.version, "satellite": ep.satellite, "fors": [r.to_dict() for r in rows]}, indent=1
            )
        )
        return EXIT_OK
    print(
        f"EP {ep.version} geolocation vs the files' own latitude/longitude ({len(args.files)} file(s)), "
        "metres"
    )
    print(f"{'FOR':>3} {'FOVs':>6} {'median':>8} {'p99':>8} {'max':>8}")
    for r in rows:
        print(f"{r.for_index:>3} {r.n:>6} {r.median_m:8.1f} {r.p99_m:8.1f} {r.max_m:8.1f}")
    return EXIT_OK


@command(
    "assess",
    "assess CrIS geolocation against VIIRS I5 for the granules given",
    arg(
        "paths",
        nargs="+",
        help="granule files or directories; or the reference implementation's collocation files (.npz)",
    ),
    arg("--out", help="write the result JSON here"),
    arg(
        "--steps",
        type=int,
        default=ASSESSMENT.half_steps,
        help="perturbation steps each side of zero (grid 2n+1; collocation files carry their own grid)",
    ),
    arg("--step-urad", type=float, default=ASSESSMENT.step_urad, help="perturbation step, urad"),
    KERNEL,
    COST,
    WORKERS,
)
def cmd_assess(args: argparse.Namespace) -> int:
    """crisgeo assess: assess the granules given; print the table, write the JSON."""
    from monitor.assessment.assess import assess_paths

    cfg = _options(
        AssessmentConfig,
        "--steps/--step-urad/--workers",
        half_steps=args.steps,
        step_urad=args.step_urad,
        kernel=args.kernel,
        cost=args.cost,
        workers=args.workers,
    )
    collocations = [p for p in args.paths if p.endswith(".npz")]
    if collocations and len(collocations) != len(args.paths):
        raise BadInput("give either granules or collocation files (.npz), not both")
    if collocations:
        from monitor.assessment.replay import assess_collocations

        result = assess_collocations(collocations, cfg)
    else:
        result = assess_paths(args.paths, cfg, workers=cfg.workers)
    print(result_text(result))
    if args.out:
        Path(args.out).write_text(result.to_json())
        print(f"wrote {args.out}")
    return EXIT_OK


def _load(args: argparse.Namespace, writes: bool = False) -> Config:
    """The configuration of *args*; with *writes*, its state directory made (the commands that write)."""

    from monitor.config.file import load_config, make_state_dir
    from monitor.config.model import ConfigError

    args.config = args.config or os.environ.get("CRISGEO_CONFIG") or DEFAULT_CONFIG
    try:
        cfg = load_config(args.config)
        if writes:
            make_state_dir(cfg)
        return cfg
    except ConfigError as exc:
        msg = str(exc)
        named = msg.startswith((str(args.config), str(Path(args.config))))  # most errors name the file
        raise BadInput(msg if named else f"{args.config}: {msg}") from None


@command(
    "install-files",
    "copy the shipped configs, Grafana and Prometheus files, EP files, the unit and docs into a directory",
    arg("dest", type=Path, help="target directory, e.g. /opt/crisgeo/share"),
    arg("--force", action="store_true", help="replace files that exist"),
)
def cmd_install_files(args: argparse.Namespace) -> int:
    """crisgeo install-files: copy the shipped files out."""
    from monitor.service.install import install_files, kept_files

    kept = [] if args.force else kept_files(args.dest)
    for path in install_files(args.dest, args.force):
        print(f"wrote {path}")
    for path in kept:
        print(f"kept  {path} (exists; --force replaces it)")
    return EXIT_OK


@command(
    "check-config",
    "validate a configuration; print it with its defaults, secrets masked",
    CONFIG,
    arg("--reference", action="store_true", help="print the reference of every key (Markdown) instead"),
    arg("--schema", action="store_true", help="print the JSON Schema of the file instead (for editors)"),
)
def cmd_check_config(args: argparse.Namespace) -> int:
    """crisgeo check-config: validate and print the effective configuration, or the reference."""
    import yaml

    from monitor.config.file import effective, json_schema, secret_status

    if args.schema:
        print(json_schema(), end="")
        return EXIT_OK
    if args.reference:
        from monitor.config.reference import reference

        print(reference(), end="")
        return EXIT_OK
    cfg = _load(args)
    print(f"# {args.config}: valid; with every default (this output loads as a configuration)")
    for where, variable, is_set in secret_status(cfg):
        print(f"# secret {where}: {variable} ({'set' if is_set else 'not set'})")
        if not is_set:  # the file is valid; the service would fail to send
            print(f"crisgeo check-config: warning: {where}: {variable} is not set", file=sys.stderr)
    print(yaml.safe_dump(effective(cfg), sort_keys=False, default_flow_style=False), end="")
    return EXIT_OK


@command(
    "export",
    "per-FOR results as CF NetCDF (xarray) or CSV",
    CONFIG,
    arg("--format", choices=("netcdf", "csv"), help="netcdf or csv (default: from the suffix of --out)"),
    arg("--out", required=True, help="the file to write: FILE.nc (NetCDF) or FILE.csv"),
    arg("--satellite", choices=tuple(SATELLITES)),
    arg("--since", type=_day, help="first day, YYYY-MM-DD"),
    arg("--until", type=_day, help="last day, YYYY-MM-DD"),
)
def cmd_export(args: argparse.Namespace) -> int:
    """crisgeo export: the results as NetCDF or CSV."""
    from monitor.service.export import ExportFormatError, NothingToExport, export

    cfg = _load(args)
    sats = _satellites(cfg, args.satellite)
    if len(sats) > 1:
        raise BadInput(f"--satellite: one of {', '.join(sats)} (a file holds one satellite)")
    _period(args.since, args.until)
    with _open_store(cfg) as store:
        try:
            path = export(store, sats[0], args.out, args.format, args.since, args.until, cfg.export)
        except ImportError as exc:
            raise BadInput(
                f"export needs the optional extra: pip install 'crisgeo-monitor[export]' ({exc})"
            ) from None
        except (NothingToExport, ExportFormatError) as exc:
            raise BadInput(str(exc)) from None
        except OSError as exc:
            raise BadInput(f"--out {args.out}: {exc.strerror or exc}") from None
    print(f"wrote {path}")
    return EXIT_OK


def _open_store(cfg: Config) -> Store:
    """The configured store for a command that only reads: never created (a missing one is an error)."""
    from monitor.service.store.sqlite import Store

    return Store(cfg.store.path, create=False)


def _period(since: dt.date | None, until: dt.date | None) -> None:
    """Refuse (bad input) a period that ends before it starts."""
    if since and until and since > until:
        raise BadInput(f"--since {since} is after --until {until}")


def _satellites(cfg: Config, satellite: str | None) -> list[str]:
    """The configured satellites, or the one asked for (which must be configured)."""
    if satellite and satellite not in cfg.satellites:
        raise BadInput(f"satellite {satellite!r} is not in the configuration ({', '.join(cfg.satellites)})")
    return [satellite] if satellite else list(cfg.satellites)


def _in_mission(sats: list[str], days: dict[str, dt.date | None]) -> None:
    """Refuse (bad input) a day given as *days* (option -> day) that no satellite of *sats* can have data
    of: before its launch, or after today."""
    today = dt.datetime.now(dt.timezone.utc).date()
    for option, day in days.items():
        for sat in sats:
            problem = SATELLITES[sat].outside_mission(day, today) if day is not None else None
            if problem:
                raise BadInput(f"{option} {day}: {problem}: no {sat} data to assess")


@command(
    "run",
    "one run of the daily job (the missed days, or --date), then exit",
    CONFIG,
    arg("--satellite", choices=tuple(SATELLITES)),
    arg("--date", type=_day, help="the UTC day to (re)assess, YYYY-MM-DD"),
)
def cmd_run(args: argparse.Namespace) -> int:
    """crisgeo run: one run of the daily job, then exit."""
    from monitor.core.vocabulary import RunStatus
    from monitor.service.daemon import Service

    cfg = _load(args, writes=True)
    sats = _satellites(cfg, args.satellite)
    _in_mission(sats, {"--date": args.date})
    bar = None
    if sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(unit="granule", desc="assessing")
    service = Service(cfg, progress=(lambda g: bar.update(1)) if bar else None)
    service.handle_signals()
    try:
        outcomes = service.run_once(sats, args.date)
    finally:
        if bar is not None:
            bar.close()
    for o in outcomes:
        print(f"{o.satellite} {o.day}: {o.status}" + (f" ({o.reason})" if o.reason else ""))
        if o.result is not None:
            print(result_text(o.result))
        if o.timings:
            print("wall time per stage: " + ", ".join(f"{k} {v:.1f} s" for k, v in o.timings.items()))
    if not outcomes and service.stopped_by is None:
        print("nothing to do: every day of the catch-up window is done")
    if service.stopped_by is not None:  # the shell's convention: 130 for SIGINT, 143 for SIGTERM
        return 128 + service.stopped_by
    return EXIT_FAIL if any(o.status == RunStatus.FAILED for o in outcomes) else EXIT_OK


@command(
    "reprocess",
    "assess a period on a Dask cluster (resumable; the days already done are skipped)",
    CONFIG,
    arg("--since", type=_day, required=True, help="first day, YYYY-MM-DD"),
    arg("--until", type=_day, required=True, help="last day, YYYY-MM-DD"),
    arg("--satellite", choices=tuple(SATELLITES)),
    arg("--scheduler", help="address of a running Dask scheduler (tcp://HOST:8786); default a local cluster"),
    arg("--workers", type=_whole(1), default=2, help="processes of the local cluster (default 2)"),
    arg("--force", action="store_true", help="redo the days already done"),
)
def cmd_reprocess(args: argparse.Namespace) -> int:
    """crisgeo reprocess: a period on Dask; this process alone writes the store."""
    from monitor.core.vocabulary import RunStatus
    from monitor.service.reprocess import run_reprocess

    cfg = _load(args, writes=True)
    sats = _satellites(cfg, args.satellite)
    _period(args.since, args.until)
    _in_mission(sats, {"--since": args.since, "--until": args.until})
    summary = run_reprocess(cfg, args.since, args.until, sats, args.scheduler, args.workers, args.force)
    for line in summary.lines():
        print(line)
    return EXIT_FAIL if summary.unfinished or summary.statuses.get(RunStatus.FAILED) else EXIT_OK


@command(
    "daemon",
    "the long-running service (systemd)",
    CONFIG,
    arg(
        "--listen",
        metavar="HOST:PORT",
        help="serve /metrics, /healthz, /report/ here (overrides http.listen; off: no endpoint)",
    ),
)
def cmd_daemon(args: argparse.Namespace) -> int:
    """crisgeo daemon: the long-running service."""
    from monitor.service.daemon import Service

    cfg = _load(args, writes=True)
    if args.listen is not None:
        from monitor.config.model import check_listen

        try:
            check_listen(args.listen)
        except ValueError as exc:
            raise BadInput(f"--listen: {exc}") from None
    Service(cfg).daemon(args.listen)  # a port taken or not allowed is an OSError: main says it
    return EXIT_OK


@command(
    "status",
    "last run per satellite, latest per-FOR table, next run, outbox size",
    CONFIG,
    arg("--satellite", choices=tuple(SATELLITES), help="only this satellite (default: every configured one)"),
    arg("--json", action="store_true", help="machine-readable status"),
)
def cmd_status(args: argparse.Namespace) -> int:
    """crisgeo status: the state of every satellite, as text or JSON, with Nagios exit codes."""
    import json

    from monitor.config.model import ConfigError
    from monitor.service.status import NagiosState, status_report
    from monitor.service.store.sqlite import Store, StoreError

    try:
        cfg = _load(args)
        sats = _satellites(cfg, args.satellite)
        store = Store(cfg.store.path, create=False)
    except (BadInput, ConfigError, StoreError) as exc:
        if args.json:
            print(json.dumps({"state": "UNKNOWN", "exit": NagiosState.UNKNOWN, "error": str(exc)}))
        else:
            print(f"UNKNOWN - {exc}")
        return NagiosState.UNKNOWN
    with store:
        status = status_report(cfg, store, sats)
    print(json.dumps(status.to_dict(), indent=1, default=str) if args.json else status.text())
    return status.state


@command(
    "alerts",
    "the alerts: list them, silence or unsilence a rule, evaluate the rules now",
    arg(
        "action",
        choices=("list", "silence", "unsilence", "evaluate"),
        nargs="?",
        default="list",
        help="list (default): firing, silenced and recently resolved alerts and the silences in force; "
        "silence: quiet --rule/--satellite until --until, with --reason; unsilence: end silence --id; "
        "evaluate: evaluate the rules and deliver now",
    ),
    CONFIG,
    arg("--rule", choices=RULES, help="silence: the rule (default: every rule)"),
    arg("--satellite", choices=tuple(SATELLITES), help="silence: the satellite (default: every one)"),
    arg("--until", type=_until, help="silence: its end (ISO 8601, UTC) or how long from now (12h, 7d)"),
    arg("--reason", default="", help="silence: why (shown with the silence)"),
    arg("--id", type=int, help="unsilence: the silence's number (crisgeo alerts list shows it)"),
    arg("--json", action="store_true", help="list: as JSON"),
)
def cmd_alerts(args: argparse.Namespace) -> int:
    """crisgeo alerts: list, silence, unsilence, evaluate."""
    from alerts.engine import alerts_view, evaluate_and_deliver
    from monitor.service.store.alerts import AlertState
    from monitor.service.store.sqlite import Store

    now = dt.datetime.now(dt.timezone.utc)
    if args.action == "list":
        cfg = _load(args)
        with _open_store(cfg) as store:
            view = alerts_view(store, now)
        if args.json:
            import json

            print(json.dumps(view.to_dict(), indent=1))
        else:
            print(view.text())
        return EXIT_OK
    cfg = _load(args, writes=True)
    with Store(cfg.store.path) as store:
        if args.action == "silence":
            if args.until is None or not args.reason:
                raise BadInput("alerts silence needs --until and --reason")
            if args.until <= now:
                raise BadInput("--until must be in the future")
            AlertState(store).silence(args.rule, args.satellite, args.until, args.reason, now)
            print(
                f"silenced rule={args.rule or '*'} satellite={args.satellite or '*'} until "
                f"{args.until:%Y-%m-%d %H:%M} UTC"
            )
        elif args.action == "unsilence":
            if args.id is None:
                raise BadInput("alerts unsilence needs --id (crisgeo alerts list shows the silences)")
            if not AlertState(store).lift(args.id, now):
                raise BadInput(f"--id {args.id}: no silence in force has that number")
            print(f"silence {args.id} lifted")
        else:
            print(evaluate_and_deliver(store, cfg.alerts, cfg.satellites, now).text())
    return EXIT_OK


@command(
    "events",
    "list the known changes, or add one to the events calendar",
    arg(
        "action",
        choices=("list", "add"),
        nargs="?",
        default="list",
        help="list (default): the calendar's changes and those found in the data; add: a change to the "
        "calendar (its comments are kept)",
    ),
    CONFIG,
    arg("--satellite", choices=tuple(SATELLITES), help="list: only this satellite; add: the satellite"),
    arg("--time", type=_iso, help="add: when (ISO 8601, UTC)"),
    arg("--instrument", choices=("cris", "viirs", "common"), help="add: the instrument changed"),
    arg("--kind", default="change", help="add: ep_upload, lut_change, software, ..."),
    arg("--description", help="add: what changed"),
)
def cmd_events(args: argparse.Namespace) -> int:
    """crisgeo events: list the known changes, or add one to the calendar."""
    from monitor.core.changes import Change, add_to_calendar, all_changes

    cfg = _load(args)
    if cfg.events_file is None:
        raise BadInput("alerts.events_file is not set in the configuration")
    if args.action == "add":
        if not (args.satellite and args.time and args.instrument and args.description):
            raise BadInput("events add needs --satellite, --time, --instrument and --description")
        try:
            add_to_calendar(
                cfg.events_file,
                Change(args.time, args.satellite, args.instrument, args.kind, args.description, "calendar"),
            )
        except OSError as exc:
            raise BadInput(f"{cfg.events_file}: {exc.strerror or exc}") from None
        except ValueError as exc:  # its message names the file
            raise BadInput(str(exc)) from None
        print(f"added to {cfg.events_file}")
        return EXIT_OK
    calendar = _calendar(cfg.events_file)
    known = {c.satellite for c in calendar} | set(cfg.satellites)
    chosen = [args.satellite] if args.satellite else [s for s in SATELLITES if s in known]
    if not cfg.store.path.exists():  # before the first run: the calendar alone
        for c in sorted(calendar, key=lambda c: c.time):
            if c.satellite in chosen:
                print(f"{c.satellite} {c.label()}")
        return EXIT_OK
    with _open_store(cfg) as store:
        for sat in chosen:
            for c in all_changes(store, sat, cfg.events_file):
                print(f"{sat} {c.label()}")
    return EXIT_OK


def _calendar(path: str | Path) -> list[Change]:
    """The events calendar at *path*; a calendar that does not load is bad input, named."""
    from monitor.core.changes import load_calendar

    try:
        return load_calendar(path)
    except OSError as exc:
        raise BadInput(f"{path}: {exc.strerror or exc}") from None
    except ValueError as exc:  # its message names the file and the entry
        raise BadInput(str(exc)) from None


@command(
    "fingerprint",
    "per-FOR LOS fingerprint (SBF angles) of CrIS GEO files",
    arg("paths", nargs="+"),
    arg("--json", action="store_true"),
    arg(
        "--threshold-urad",
        type=float,
        default=FINGERPRINT.threshold_urad,
        help=f"a processing change: a FOR moving more (default {FINGERPRINT.threshold_urad:g}, fingerprint."
        "threshold_urad)",
    ),
    arg(
        "--ep-library",
        action="append",
        metavar="PATH",
        help="EP file or directory to identify the EP from (repeatable; default: the packaged real EPs)",
    ),
    arg(
        "--write-residuals",
        metavar="FILE",
        help="write the per-FOR FOV-5 LOS residual against --ep (default: the best-matching EP)",
    ),
    arg("--ep", help="the EP the residual table is learned against (XML or YAML)"),
)
def cmd_fingerprint(args: argparse.Namespace) -> int:
    """crisgeo fingerprint: the per-FOR LOS fingerprint of GEO files."""
    import json

    from monitor.mapping import fingerprint as fpr

    f = _options(
        FingerprintConfig,
        "--threshold-urad/--ep-library",
        threshold_urad=args.threshold_urad,
        ep_library=args.ep_library or [],
    )
    fp = fpr.fingerprint_files(args.paths, f.ep_library, f.threshold_urad)
    if args.json:
        print(json.dumps(fp.to_dict(), indent=1))
    else:
        print(fpr.format_print(fp.verdict.day))
        for s in fp.skipped:
            print(f"skipped {s}")
        c = fp.verdict.change
        print(
            "no step within these granules"
            if c is None
            else f"step from granule {c.granule} at FOR {', '.join(map(str, c.fors))}"
        )
        print(fpr.format_matches(fp.verdict.matches))
        for p in fp.problems:
            print(f"EP library: {p}")
    if args.write_residuals:
        _write_residuals(args, fp.verdict.day, fp.verdict.matches, fp.library)
    return EXIT_OK


def _write_residuals(
    args: argparse.Namespace, day: DayPrint, matches: Sequence[EpMatch], library: dict[str, EngineeringPacket]
) -> None:
    from monitor.mapping.residuals import learn

    if args.ep:
        ep = _ep(args.ep)
    elif matches:
        ep = library[matches[0].name]
    else:
        raise BadInput(
            "--write-residuals: no EP to learn against (give --ep or an --ep-library of this satellite)"
        )
    table = learn(day, ep)
    table.write(args.write_residuals)
    print(
        f"wrote residual table against EP {ep.version} ({len(day.granules)} granule(s)) to "
        f"{args.write_residuals}",
        file=sys.stderr if args.json else sys.stdout,
    )


@command(
    "report",
    "the self-contained HTML trend report (one page per satellite)",
    CONFIG,
    arg("--out", help="output directory (default: report_dir of the configuration)"),
    arg("--satellite", choices=tuple(SATELLITES)),
    arg("--since", type=_day, help="first day shown, YYYY-MM-DD"),
    arg("--until", type=_day, help="last day shown, YYYY-MM-DD"),
)
def cmd_report(args: argparse.Namespace) -> int:
    """crisgeo report: write the HTML report."""
    import time

    from monitor.service.report.html import build_report, options_from_config

    cfg = _load(args)
    _satellites(cfg, args.satellite)
    _period(args.since, args.until)
    opts = options_from_config(cfg, [args.satellite] if args.satellite else None, args.since, args.until)
    t0 = time.perf_counter()
    with _open_store(cfg) as store:
        index = build_report(store, args.out or cfg.report_dir or "report", opts)
    print(f"wrote {Path(index).resolve()} ({', '.join(opts.satellites)}) in {time.perf_counter() - t0:.1f} s")
    return EXIT_OK


@command(
    "bench",
    "time each stage on a simulated case; print FOVs/s and peak memory",
    arg("--granules", type=_whole(1), default=14),
    arg("--data", help="case directory to reuse or create (default: a temporary directory)"),
    arg("--pyresample", action="store_true", help="also time pyresample's radius search as a reference"),
    WORKERS,
    COST,
    KERNEL,
)
def cmd_bench(args: argparse.Namespace) -> int:
    """crisgeo bench: time each stage on a simulated case."""
    from monitor.assessment.bench import run_bench

    cfg = _options(AssessmentConfig, "--workers", cost=args.cost, kernel=args.kernel, workers=args.workers)
    return run_bench(args, cfg)


class _PrintReference(argparse.Action):
    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: object,
        option_string: str | None = None,
    ) -> None:
        print(cli_reference(parser), end="")
        parser.exit()


def cli_reference(parser: argparse.ArgumentParser) -> str:
    """Every command with its usage and options, as Markdown (docs/cli.md is its output)."""

    out = [
        "# The crisgeo command line",
        "",
        "Generated by `crisgeo --cli-reference > docs/cli.md` (a test keeps it equal).",
        "",
        "```",
        _plain_help(parser),
        "```",
    ]
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, sp in sub.choices.items():
        out += ["", f"## crisgeo {name}", "", COMMANDS[name][1][:1].upper() + COMMANDS[name][1][1:] + ".", ""]
        out += ["```", _plain_help(sp), "```"]
    os.environ.pop("COLUMNS", None)
    return "\n".join(out) + "\n"


def _plain_help(parser: argparse.ArgumentParser) -> str:

    os.environ["COLUMNS"] = "110"  # the same wrapping on every terminal
    return parser.format_help().rstrip()


def build_parser() -> argparse.ArgumentParser:
    """The argument parser: the global options and one subparser per entry of :data:`COMMANDS`."""
    p = argparse.ArgumentParser(
        prog="crisgeo",
        description=__doc__.replace("``", ""),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    p.add_argument("--version", action="version", version=f"crisgeo {__version__}")
    p.add_argument(
        "--cli-reference",
        action=_PrintReference,
        help="print the reference of every command and option (Markdown: docs/cli.md) and exit",
    )
    p.add_argument(
        "--log-format",
        choices=("text", "json"),
        default="text",
        help="text (no timestamp under systemd: the journal adds one) or JSON lines",
    )
    common = argparse.ArgumentParser(add_help=False)  # -v and --log-format after the subcommand too
    common.add_argument(
        "-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help="debug logging"
    )
    common.add_argument(
        "--log-format", choices=("text", "json"), default=argparse.SUPPRESS, help="text or JSON lines"
    )
    sub = p.add_subparsers(dest="command", required=True)
    for name, (handler, help_text, arguments) in COMMANDS.items():
        sp = sub.add_parser(name, help=help_text, parents=[common])
        for names, options in arguments:
            sp.add_argument(*names, **options)
        sp.set_defaults(func=handler)
    return p


class _PipedOutput:
    """Standard output that a reader closing the pipe (``| head -1``) silences instead of ending the
    command: the exit status stays the one computed (a Nagios check piped into head still says 2)."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self.gone = False

    def write(self, text: str) -> int:
        if not self.gone:
            try:
                return self._stream.write(text)
            except BrokenPipeError:
                self._close()
        return len(text)

    def flush(self) -> None:
        if not self.gone:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._close()

    def _close(self) -> None:
        self.gone = True
        # the interpreter flushes stdout once more at exit: what is left goes to /dev/null, not to a
        # "BrokenPipeError ignored" and exit status 120
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, self._stream.fileno())
        os.close(null)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def main(argv: Sequence[str] | None = None) -> int:
    """The crisgeo command: parse, set up logging, run the subcommand; its exit status. Every error a
    command lets through is mapped to its exit status here, in one line: bad input (2), another instance
    (75), an unusable store or the machine's (1), an interruption (130)."""
    from monitor.service.lock import AlreadyRunning
    from monitor.service.store.sqlite import StoreError

    parser = build_parser()
    args = parser.parse_args(argv)
    logs.setup(args.verbose, args.log_format)
    allocator.reuse_freed_memory()
    stdout = sys.__stdout__
    if stdout is not None and sys.stdout is stdout:
        sys.stdout = _PipedOutput(stdout)
    try:
        code = args.func(args)
        sys.stdout.flush()
        return code
    except (BadInput, DataError) as exc:  # the input's fault, named in one line
        print(f"crisgeo {args.command}: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except AlreadyRunning as exc:
        print(f"crisgeo {args.command}: {exc}", file=sys.stderr)
        return EXIT_ALREADY_RUNNING
    except StoreError as exc:
        print(f"crisgeo {args.command}: {exc}", file=sys.stderr)
        return EXIT_FAIL
    except OSError as exc:  # the machine's, not the input's (a full disk, a lost mount): one line naming it
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"crisgeo {args.command}: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_FAIL
    except KeyboardInterrupt:
        return 130

