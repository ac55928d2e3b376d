"""The operator's commands: install the files, check the configuration, run a day, reprocess, the daemon,
the status (a Nagios plugin)."""

from __future__ import annotations

import argparse
import datetime as dt
import sys
from pathlib import Path

from monitor.cli.output import result_text
from monitor.cli.progress import Progress
from monitor.cli.registry import (
    CONFIG,
    EXIT_FAIL,
    EXIT_OK,
    SATELLITE,
    BadInput,
    arg,
    command,
    load,
    period,
    satellites_of,
)
from monitor.cli.types import iso_day, nagios_range, whole
from monitor.core.constants import SPEC_KM
from monitor.core.satellites import SATELLITES


@command(
    "install-files",
    "copy the shipped configs, Grafana and Prometheus files, EP files, the unit and docs into a directory",
    arg("dest", type=Path, help="target directory, e.g. /opt/crisgeo/share"),
    arg("--force", action="store_true", help="replace files that exist"),
    arg(
        "--config",
        help="configuration file whose alerts.spec_km the Grafana dashboards' thresholds are written at "
        "(default: the default specification)",
    ),
)
def cmd_install_files(args: argparse.Namespace) -> int:
    """crisgeo install-files: copy the shipped files out.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.service.install import install_files, kept_files

    spec_km = load(args).alerts.spec_km if args.config else SPEC_KM
    kept = [] if args.force else kept_files(args.dest)
    for path in install_files(args.dest, args.force, spec_km):
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
    """crisgeo check-config: validate and print the effective configuration, or the reference.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    import yaml

    from monitor.config.file import effective, json_schema, secret_status

    if args.schema:
        print(json_schema(), end="")
        return EXIT_OK
    if args.reference:
        from monitor.config.reference import reference

        print(reference(), end="")
        return EXIT_OK
    cfg = load(args)
    print(f"# {args.config}: valid; with every default (this output loads as a configuration)")
    for where, variable, is_set in secret_status(cfg):
        print(f"# secret {where}: {variable} ({'set' if is_set else 'not set'})")
        if not is_set:  # the file is valid; the service would fail to send
            print(f"crisgeo check-config: warning: {where}: {variable} is not set", file=sys.stderr)
    print(yaml.safe_dump(effective(cfg), sort_keys=False, default_flow_style=False), end="")
    return EXIT_OK


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
    SATELLITE,
    arg("--date", type=iso_day, help="the UTC day to (re)assess, YYYY-MM-DD"),
)
def cmd_run(args: argparse.Namespace) -> int:
    """crisgeo run: one run of the daily job, then exit.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.core.vocabulary import RunStatus
    from monitor.service.daemon import Service

    cfg = load(args, writes=True)
    sats = satellites_of(cfg, args.satellite)
    _in_mission(sats, {"--date": args.date})
    # a bar with the batches' totals on a terminal; off it, the day's own lines (the journal's)
    with Progress("assessing granules") as progress:
        service = Service(cfg, progress=progress if progress.bar is not None else None)
        service.handle_signals()
        outcomes = service.run_once(sats, args.date)
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
    arg("--since", type=iso_day, required=True, help="first day, YYYY-MM-DD"),
    arg("--until", type=iso_day, required=True, help="last day, YYYY-MM-DD"),
    SATELLITE,
    arg("--scheduler", help="address of a running Dask scheduler (tcp://HOST:8786); default a local cluster"),
    arg("--processes", type=whole(1), default=2, help="processes of the local Dask cluster (default 2)"),
    # the earlier name, kept for scripts
    arg("--workers", dest="processes", type=whole(1), help=argparse.SUPPRESS),
    arg("--force", action="store_true", help="redo the days already done"),
)
def cmd_reprocess(args: argparse.Namespace) -> int:
    """crisgeo reprocess: a period on Dask; this process alone writes the store.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.core.vocabulary import RunStatus
    from monitor.service.reprocess import run_reprocess

    cfg = load(args, writes=True)
    sats = satellites_of(cfg, args.satellite)
    period(args.since, args.until)
    _in_mission(sats, {"--since": args.since, "--until": args.until})
    summary = run_reprocess(cfg, args.since, args.until, sats, args.scheduler, args.processes, args.force)
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
    """crisgeo daemon: the long-running service.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.service.daemon import Service

    cfg = load(args, writes=True)
    if args.listen is not None:
        from monitor.config.keys import check_listen

        try:
            check_listen(args.listen)
        except ValueError as exc:
            raise BadInput(f"--listen: {exc}") from None
    service = Service(cfg)
    service.daemon(args.listen)  # a port taken or not allowed is an OSError: main says it
    # stopped by a signal: the shell's 128 + it (143 for systemctl stop: the unit's SuccessExitStatus)
    return EXIT_OK if service.stopped_by is None else 128 + service.stopped_by


@command(
    "status",
    "last run per satellite, latest per-FOR table, next run, outbox size; a Nagios plugin",
    CONFIG,
    SATELLITE,
    arg("--json", action="store_true", help="machine-readable status"),
    arg(
        "-w",
        "--warning",
        type=nagios_range,
        help="WARNING range of the worst error, km (monitoring-plugins syntax; default: the specification)",
    ),
    arg("-c", "--critical", type=nagios_range, help="CRITICAL range of the worst error, km (default: none)"),
    arg(
        "--warning-fors",
        type=nagios_range,
        help="WARNING range of the count of FORs beyond the specification",
    ),
    arg(
        "--critical-fors",
        type=nagios_range,
        help="CRITICAL range of the count of FORs beyond the specification",
    ),
    arg(
        "--stale-days",
        type=float,
        default=2.0,
        help="WARNING after this many days without a successful assessment (default 2)",
    ),
    arg("-t", "--timeout", type=float, default=30.0, help="UNKNOWN after this many seconds (default 30)"),
)
def cmd_status(args: argparse.Namespace) -> int:
    """crisgeo status: the state of every satellite, as text or JSON, with Nagios exit codes.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    import json
    import signal
    from types import FrameType

    from nagiosplugin import Range

    from monitor.config.keys import ConfigError
    from monitor.service.status import NagiosState, Thresholds, status_report
    from monitor.service.store.database import StoreError
    from monitor.service.store.sqlite import Store

    class Expired(Exception):
        """-t ran out (not a TimeoutError: that is an OSError, the machine's fault to main)."""

    def expired(signum: int, frame: FrameType | None) -> None:
        raise Expired(f"no answer within {args.timeout:g} s (-t)")

    previous = signal.signal(signal.SIGALRM, expired)
    try:
        signal.setitimer(signal.ITIMER_REAL, args.timeout)
        cfg = load(args)
        sats = satellites_of(cfg, args.satellite)
        with Store(cfg.store.path, create=False) as store:
            thresholds = Thresholds(
                args.warning or Range(f"{cfg.alerts.spec_km:g}"),
                args.critical,
                args.warning_fors,
                args.critical_fors,
                args.stale_days,
            )
            status = status_report(cfg, store, sats, thresholds=thresholds)
    except (BadInput, ConfigError, StoreError, Expired) as exc:
        if args.json:
            print(json.dumps({"state": "UNKNOWN", "exit": NagiosState.UNKNOWN, "error": str(exc)}))
        else:
            print(f"UNKNOWN - {exc}")
        return NagiosState.UNKNOWN
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    print(json.dumps(status.to_dict(), indent=1, default=str) if args.json else status.text())
    return status.state
