"""The results' commands: export as NetCDF or CSV, the HTML report."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from monitor.cli.registry import (
    CONFIG,
    EXIT_OK,
    SATELLITE,
    BadInput,
    arg,
    command,
    load,
    open_store,
    period,
    satellites_of,
)
from monitor.cli.types import iso_day


@command(
    "export",
    "per-FOR results, or what each known change did, as CF NetCDF (xarray) or CSV",
    CONFIG,
    arg(
        "--changes",
        action="store_true",
        help="what each known change did (as crisgeo events effects shows it), not the daily results",
    ),
    arg("--format", choices=("netcdf", "csv"), help="netcdf or csv (default: from the suffix of --out)"),
    arg("--out", required=True, help="the file to write: FILE.nc (NetCDF) or FILE.csv"),
    SATELLITE,
    arg("--since", type=iso_day, help="first day, YYYY-MM-DD"),
    arg("--until", type=iso_day, help="last day, YYYY-MM-DD"),
)
def cmd_export(args: argparse.Namespace) -> int:
    """crisgeo export: the results, or what each known change did, as NetCDF or CSV.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from alerts.effects import change_effects
    from monitor.history.changes import all_changes
    from monitor.service.outputs.export import Method, NothingToExport, export, export_effects

    cfg = load(args)
    sats = satellites_of(cfg, args.satellite)
    if len(sats) > 1:
        raise BadInput(f"--satellite: one of {', '.join(sats)} (a file holds one satellite)")
    period(args.since, args.until)
    with open_store(cfg) as store:
        try:
            if args.changes:
                known = change_effects(
                    store, sats[0], all_changes(store, sats[0], cfg.events_file), cfg.alerts
                )
                effects = [
                    e
                    for e in known
                    if (args.since is None or e.day >= args.since)
                    and (args.until is None or e.day <= args.until)
                ]
                path = export_effects(effects, sats[0], args.out, args.format, cfg.export)
            else:
                path = export(
                    store, sats[0], args.out, args.format, args.since, args.until, cfg.export, Method.of(cfg)
                )
        except ImportError as exc:
            raise BadInput(
                f"export needs the optional extra: pip install 'crisgeo-monitor[export]' ({exc})"
            ) from None
        except NothingToExport as exc:  # an empty period is an answer, not bad input
            print(f"nothing to export: {exc}", file=sys.stderr)
            return EXIT_OK
        except ValueError as exc:  # ExportFormatError, a calendar entry: named
            raise BadInput(str(exc)) from None
        except OSError as exc:
            raise BadInput(f"--out {args.out}: {exc.strerror or exc}") from None
    print(f"wrote {path}")
    return EXIT_OK


@command(
    "report",
    "the self-contained HTML trend report (one page per satellite)",
    CONFIG,
    arg("--out", help="output directory (default: report_dir of the configuration)"),
    SATELLITE,
    arg("--since", type=iso_day, help="first day shown, YYYY-MM-DD"),
    arg("--until", type=iso_day, help="last day shown, YYYY-MM-DD"),
)
def cmd_report(args: argparse.Namespace) -> int:
    """crisgeo report: write the HTML report.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    import time

    from monitor.service.outputs.report.html import build_report, options_from_config

    cfg = load(args)
    satellites_of(cfg, args.satellite)
    period(args.since, args.until)
    opts = options_from_config(cfg, [args.satellite] if args.satellite else None, args.since, args.until)
    t0 = time.perf_counter()
    out = args.out or cfg.report_dir or "report"
    with open_store(cfg) as store:
        if (args.since or args.until) and not any(
            store.series(s, args.since, args.until) for s in opts.satellites
        ):
            # a period with no results would replace the live report with empty pages
            print(
                f"no results of {', '.join(opts.satellites)} in {args.since or 'the beginning'} .. "
                f"{args.until or 'the end'}: the report in {Path(out).resolve()} is left as it was",
                file=sys.stderr,
            )
            return EXIT_OK
        index = build_report(store, out, opts)
    print(f"wrote {Path(index).resolve()} ({', '.join(opts.satellites)}) in {time.perf_counter() - t0:.1f} s")
    return EXIT_OK
