"""The mapping-angle commands: the LOS fingerprint of GEO files, geolocation with an EP, regeolocation,
the mapping-angle optimiser."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from monitor.cli.registry import EXIT_FAIL, EXIT_OK, FINGERPRINT, BadInput, arg, command, ep_file, options
from monitor.config.assessment import FingerprintConfig
from monitor.core.errors import DataError

if TYPE_CHECKING:  # the commands import what they run when they run it: crisgeo starts fast
    from monitor.geometry.ep_model import EngineeringPacket
    from monitor.mapping.fingerprint import DayPrint
    from monitor.mapping.identify import EpMatch
    from monitor.mapping.residuals import OwnResiduals, ResidualTable

RESIDUAL_ARGS = (
    arg("--residuals", help="per-FOR LOS residual table (crisgeo fingerprint --write-residuals)"),
    arg(
        "--own-residuals",
        metavar="EP_IN_FORCE",
        help="learn each granule's residual from itself, against the EP it was made with",
    ),
)


def _residuals(args: argparse.Namespace) -> ResidualTable | OwnResiduals | None:
    """The residual table of --residuals FILE, or each granule's own against --own-residuals EP."""
    from monitor.mapping.residuals import OwnResiduals, ResidualError, load

    if args.residuals and args.own_residuals:
        raise BadInput("--residuals and --own-residuals exclude each other")
    if args.own_residuals:
        return OwnResiduals(ep_file(args.own_residuals))
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
    """crisgeo optimize: new scene-mirror angles from an assessment.

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

    from monitor.core.result import AssessmentResult
    from monitor.mapping.optimize import optimize
    from monitor.sdr.engpkt import save_ep

    try:
        result = AssessmentResult.from_json(Path(args.result).read_text())
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise BadInput(f"{args.result}: not an assessment result ({exc})") from None
    ep = ep_file(args.ep)
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
    arg("files", nargs="+", help="CrIS GEO granule files (HDF5) to geolocate again"),
    arg("--ep", required=True, help="the engineering packet to regeolocate with (XML or YAML)"),
    arg("--out", required=True, help="output directory (never the input's)"),
    *RESIDUAL_ARGS,
)
def cmd_regeolocate(args: argparse.Namespace) -> int:
    """crisgeo regeolocate: GEO copies geolocated with another EP.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.mapping.regeolocate import regeolocate_file

    ep = ep_file(args.ep)
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
    arg("files", nargs="+", help="CrIS SDR and GEO granule files (HDF5)"),
    arg("--ep", required=True, help="the engineering packet to geolocate with (XML or YAML)"),
    arg("--json", action="store_true", help="print the geolocation as JSON"),
    *RESIDUAL_ARGS,
)
def cmd_geolocate(args: argparse.Namespace) -> int:
    """crisgeo geolocate: an EP's geolocation against the files' own, per FOR.

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

    from monitor.mapping.regeolocate import compare_with_files

    ep = ep_file(args.ep)
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
    "fingerprint",
    "per-FOR LOS fingerprint (SBF angles) of CrIS GEO files",
    arg("paths", nargs="+", help="CrIS GEO granule files or directories of one day"),
    arg("--json", action="store_true", help="print the fingerprint and its matches as JSON"),
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
    """crisgeo fingerprint: the per-FOR LOS fingerprint of GEO files.

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

    from monitor.mapping import fingerprint as fpr
    from monitor.mapping import identify

    f = options(
        FingerprintConfig,
        "--threshold-urad/--ep-library",
        threshold_urad=args.threshold_urad,
        ep_library=args.ep_library or [],
    )
    fp = fpr.fingerprint_files(args.paths, f.ep_library, f.threshold_urad)
    if args.json:
        print(json.dumps(fp.to_dict(), indent=1))
    else:
        print(identify.format_print(fp.verdict.day))
        for s in fp.skipped:
            print(f"skipped {s}")
        c = fp.verdict.change
        print(
            "no step within these granules"
            if c is None
            else f"step from granule {c.granule} at FOR {', '.join(map(str, c.fors))}"
        )
        print(identify.format_matches(fp.verdict.matches))
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
        ep = ep_file(args.ep)
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
