"""The science's commands: simulate granules, assess granules or collocations, time the assessment."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from monitor.cli.output import result_text
from monitor.cli.progress import Progress
from monitor.cli.registry import (
    ASSESSMENT,
    CLOUDS,
    COST,
    EXIT_OK,
    KERNEL,
    WORKERS,
    BadInput,
    arg,
    command,
    ep_file,
    options,
    unset,
)
from monitor.cli.types import band_list, band_values_k, iso_time, longitude, satellite_name, whole
from monitor.config.assessment import AssessmentConfig
from monitor.core.bands import BANDS
from monitor.core.constants import N_FOV, PAPER_GRANULES
from monitor.instrument.footprint import SHAPES as FOOTPRINTS
from monitor.simulate import CIRRUS_BASE_M, LAYOUTS
from monitor.simulate.sun_synchronous import PASSES

if TYPE_CHECKING:  # the commands import what they run when they run it: crisgeo starts fast
    from monitor.instrument.footprint import Response


@command(
    "simulate",
    "write simulated CrIS/VIIRS granules with an injected LOS error",
    arg("--out", required=True, help="output directory"),
    arg("--satellite", type=satellite_name, metavar="S", default="j01", help="the satellite (default j01)"),
    arg(
        "--granules",
        type=whole(1),
        default=PAPER_GRANULES,
        help=f"consecutive CrIS granules (default {PAPER_GRANULES}, as the paper)",
    ),
    arg("--profile", help="paper (default), random, zero, or a JSON/YAML profile file"),
    arg("--seed", type=whole(0), help="the simulator's seed (default 0)"),
    arg("--start", type=iso_time, default=None, help="UTC start of the first granule (ISO 8601)"),
    arg("--true-ep", help="EP file (XML or YAML) the radiances are made with (with --ground-ep)"),
    arg("--ground-ep", help="EP file the GEO files are made with (the ground processing's EP)"),
    arg("--terrain", action="store_true", help="1-4 km ranges and plateaus over 40 %% land"),
    CLOUDS,
    arg(
        "--cloud-edges",
        default="soft",
        metavar="EDGES",
        help="soft (the cover fades over a few km) or sharp (blobs cut within a fine cell); default soft",
    ),
    arg(
        "--wind",
        type=float,
        default=0.0,
        metavar="M_S",
        help="the clouds move this fast along the track (m/s, + in the direction of flight) between the "
        "two instruments' views; default 0",
    ),
    arg(
        "--cloud-emissivity",
        type=float,
        default=1.0,
        metavar="E",
        help=f"the emissivity of the clouds met above {CIRRUS_BASE_M / 1e3:g} km (cirrus), 0 < E <= 1: below "
        "1 the ground shows through; lower clouds stay opaque; default 1",
    ),
    arg(
        "--fov-rows-urad",
        type=float,
        default=0.0,
        help="turn the true LOS of FOVs 7-9 in-track by +half this and of FOVs 1-3 by -half, unknown to "
        "GEO (an error of the EP's FOV positions, urad)",
    ),
    arg(
        "--pass",
        dest="orbit_pass",
        choices=sorted(PASSES),
        help="start at this pass of the satellite's orbit after --start (day: ascending tropics, "
        "night: descending, arctic/antarctic: 60-81 deg); default an ascending tropical pass",
    ),
    arg("--pass-lon", type=longitude, help="with --pass: the pass nearest this longitude, deg (e.g. 180)"),
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
        metavar="SHAPE",
        help="the CrIS FOV's spatial response, one of " + ", ".join(FOOTPRINTS) + ", stretched by :S (e.g. "
        "blurred:0.95) or unequally by :AxB@DEG (axis a DEG deg from in-track): one shape for all FOVs, "
        "or nine (FOV 1..9); default the paper's top-hat cone",
    ),
    arg(
        "--bands",
        type=band_list,
        default=("I5",),
        metavar="BANDS",
        help="the VIIRS bands written, comma-separated, of I5, M13, M15, M16 (default I5, the assessment's)",
    ),
    arg(
        "--viirs-band-bias-k",
        type=band_values_k,
        default={},
        metavar="BAND=K,...",
        help="a VIIRS calibration difference per band: K added to VIIRS's BT there (CrIS minus VIIRS reads "
        "minus it), e.g. M15=0.15",
    ),
)
def cmd_simulate(args: argparse.Namespace) -> int:
    """crisgeo simulate: write a simulated case.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.simulate.case import simulate_case

    where = dict(
        terrain=args.terrain,
        orbit_pass=args.orbit_pass,
        pass_lon_deg=args.pass_lon,
        complete=args.complete,
        layout=args.layout,
        cris_response=_footprint(args.footprint),
        cloud_heights=args.clouds,
        cloud_edges=args.cloud_edges,
        fov_rows_alpha_urad=args.fov_rows_urad,
        wind_in_track_m_s=args.wind,
        cloud_emissivity=args.cloud_emissivity,
        viirs_bands=args.bands,
        viirs_band_bias_k=args.viirs_band_bias_k,
    )
    if (args.true_ep is None) != (args.ground_ep is None):
        raise BadInput("--true-ep and --ground-ep go together")
    given = {
        "start": args.start,
        "seed": args.seed,
        "profile": args.profile,
    }  # unset: the simulator's
    case = dict(satellite=args.satellite, granules=args.granules, **where)
    case.update({k: v for k, v in given.items() if v is not None})
    if args.true_ep:
        case.update(profile="ep", true_ep=ep_file(args.true_ep), ground_ep=ep_file(args.ground_ep))
    with Progress("simulating granules") as progress:
        truth = simulate_case(args.out, progress=progress, **case)
    error = f"EP {args.true_ep} over {args.ground_ep}" if args.true_ep else f"profile {truth['profile']}"
    print(
        f"wrote {len(truth['files'])} files and truth.json to {args.out} "
        f"({args.satellite}, {args.granules} CrIS granules, VIIRS {', '.join(args.bands)}, {error}, "
        f"seed {truth['seed']})"
    )
    return EXIT_OK


def _footprint(names: Sequence[str] | None) -> Response | tuple[Response, ...] | None:
    """The spatial response of --footprint: None (the top-hat cone), one shape, or one per FOV."""
    from monitor.instrument.footprint import shape

    if not names:
        return None
    if len(names) not in (1, N_FOV):
        raise BadInput(f"--footprint takes one shape or {N_FOV} (FOV 1..{N_FOV}), not {len(names)}")
    try:
        return shape(names[0]) if len(names) == 1 else tuple(shape(n) for n in names)
    except ValueError as exc:
        raise BadInput(f"--footprint: {exc}") from None


def _assessment_in(path: str) -> AssessmentConfig:
    """The ``assessment`` section of the configuration file *path*, the others unread; a problem is bad
    input naming the file and the key."""
    from monitor.config.file import section_in_file
    from monitor.config.keys import ConfigError

    try:
        section = section_in_file(path, "assessment")
    except ConfigError as exc:
        raise BadInput(str(exc)) from None
    assert isinstance(section, AssessmentConfig)
    return section


@command(
    "assess",
    "assess CrIS geolocation against VIIRS I5 for the granules given",
    arg(
        "paths",
        nargs="+",
        help="granule files or directories; or the reference implementation's collocation files (.npz)",
    ),
    arg(
        "--config",
        help="assess as the daemon does with this configuration file's assessment section (default: the "
        "section's defaults); the options below override its keys",
    ),
    arg("--out", help="write the result JSON here"),
    arg(
        "--steps",
        type=int,
        help=f"perturbation steps each side of zero, assessment.half_steps (default {ASSESSMENT.half_steps}; "
        "grid 2n+1; collocation files carry their own grid)",
    ),
    arg(
        "--step-urad",
        type=float,
        help=f"perturbation step, urad, assessment.step_urad (default {ASSESSMENT.step_urad:.1f})",
    ),
    unset(KERNEL),
    unset(COST),
    unset(WORKERS),
)
def cmd_assess(args: argparse.Namespace) -> int:
    """crisgeo assess: assess the granules given; print the table, write the JSON.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.assessment.assess import assess_plan, in_second_band
    from monitor.assessment.daymap import with_bands
    from monitor.matchup import map_granules
    from monitor.sdr.pairing import plan

    base = _assessment_in(args.config) if args.config else ASSESSMENT
    given = {
        "half_steps": args.steps,
        "step_urad": args.step_urad,
        "kernel": args.kernel,
        "cost": args.cost,
        "workers": args.workers,
    }
    cfg = options(
        AssessmentConfig,
        "--steps/--step-urad/--kernel/--cost/--workers",
        **{**base.model_dump(mode="json"), **{k: v for k, v in given.items() if v is not None}},
    )
    collocations = [p for p in args.paths if p.endswith(".npz")]
    if collocations and len(collocations) != len(args.paths):
        raise BadInput("give either granules or collocation files (.npz), not both")
    if collocations:
        from monitor.assessment.replay import assess_collocations

        result = assess_collocations(collocations, cfg)
    else:
        case = plan(args.paths, bands=tuple(cfg.bands))
        with Progress("assessing granules", len(case.cris)) as progress:
            result = assess_plan(case, cfg, progress, workers=cfg.workers)
        if result.granules:
            matchup, _ = map_granules(args.paths, tuple(cfg.bands), offsets=result)
            result = in_second_band(case, with_bands(result, matchup, cfg), cfg)
    print(result_text(result))
    if args.out:
        Path(args.out).write_text(result.to_json())
        print(f"wrote {args.out}")
    return EXIT_OK


@command(
    "bench",
    "time each stage on a simulated case; print FOVs/s, CPU and bytes read per granule, peak memory",
    arg(
        "--granules",
        type=whole(1),
        default=PAPER_GRANULES,
        help=f"consecutive CrIS granules of the simulated case (default {PAPER_GRANULES})",
    ),
    arg("--data", help="case directory to reuse or create (default: a temporary directory)"),
    CLOUDS,
    arg("--pyresample", action="store_true", help="also time pyresample's radius search as a reference"),
    arg(
        "--map",
        action="store_true",
        help="also map the case onto every VIIRS band (simulated with I5, M13, M15, M16) and print the "
        "mapping's CPU per band, the reading apart",
    ),
    WORKERS,
    COST,
    KERNEL,
)
def cmd_bench(args: argparse.Namespace) -> int:
    """crisgeo bench: time each stage on a simulated case.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.assessment.bench import run_bench

    cfg = options(AssessmentConfig, "--workers", cost=args.cost, kernel=args.kernel, workers=args.workers)
    return run_bench(args, cfg)


@command(
    "map",
    "map every CrIS FOV onto VIIRS I5, M13, M15, M16: the VIIRS scene in each FOV and CrIS in each band",
    arg(
        "paths", nargs="+", metavar="PATH", help="granule files or directories (CrIS SDR+GEO, VIIRS SDR+GEO)"
    ),
    arg("--out", required=True, metavar="FILE.nc", help="the mapping file (NetCDF, CF-1.8/ACDD-1.3)"),
    arg(
        "--bands",
        type=band_list,
        default=tuple(BANDS),
        metavar="BANDS",
        help="the VIIRS bands, comma-separated (default I5,M13,M15,M16)",
    ),
    arg(
        "--offsets",
        metavar="RESULT.json",
        help="an assessment result (crisgeo assess --out): each FOV placed on the assessed geolocation, "
        "weighted by the day's fitted response; default the operational geolocation, the nominal response",
    ),
)
def cmd_map(args: argparse.Namespace) -> int:
    """crisgeo map: map CrIS FOVs onto VIIRS bands; write the NetCDF file.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.core.result import AssessmentResult
    from monitor.matchup import map_granules

    offsets = None
    if args.offsets:
        try:
            offsets = AssessmentResult.from_json(Path(args.offsets).read_text())
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise BadInput(f"{args.offsets}: not an assessment result ({exc})") from None
    matchup, cost = map_granules(args.paths, args.bands, offsets)
    matchup.write(args.out)
    for note in matchup.notes:
        print(f"skipped {note}")
    print(
        f"wrote {args.out}: {matchup.scans} CrIS scans x 30 x 9 FOVs on VIIRS {', '.join(matchup.bands)}, "
        f"{matchup.geolocation} geolocation, {matchup.response} response"
    )
    return EXIT_OK
