"""``crisgeo bench``: wall time of each stage of an assessment on a simulated case, FOVs/s, the CPU and the
bytes read per CrIS granule, peak memory; with ``--map``, the mapping of the case onto every VIIRS band, its
CPU per band with the reading apart."""

from __future__ import annotations

import argparse
import json
import resource
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from monitor.assessment.assess import assess_plan, offsets_rad
from monitor.collocation.collocate import warm_up
from monitor.config.assessment import AssessmentConfig
from monitor.core.bands import BANDS
from monitor.geometry import wgs84
from monitor.geometry.inverse import granule_geometry
from monitor.geometry.perturb import perturbed_los_sbf
from monitor.matchup import map_granules
from monitor.sdr import read_file
from monitor.sdr.pairing import CasePlan, plan
from monitor.simulate.case import simulate_case


def peak_rss_mb(who: int = resource.RUSAGE_SELF) -> float:
    """The peak resident memory so far.

    Parameters
    ----------
    who : int, optional
        ``resource.RUSAGE_SELF``, or ``RUSAGE_CHILDREN`` for the largest child.

    Returns
    -------
    float
        MB (Linux ru_maxrss is in KB).
    """
    return resource.getrusage(who).ru_maxrss / 1024.0


def reset_peak_rss() -> bool:
    """Start this process's peak-memory count afresh (Linux: clear_refs 5 resets VmHWM and ru_maxrss).

    Returns
    -------
    bool
        Whether it could.
    """
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def bytes_read() -> int | None:
    """The bytes this process has read through system calls so far (Linux ``/proc/self/io`` rchar: files
    read from the page cache count too, as they cost the reads).

    Returns
    -------
    int or None
        Bytes; None where the system does not count them.
    """
    try:
        for line in Path("/proc/self/io").read_text().splitlines():
            if line.startswith("rchar:"):
                return int(line.split()[1])
    except (OSError, ValueError):
        pass
    return None


def _pyresample_reference(case: CasePlan, cfg: AssessmentConfig) -> tuple[float, int] | None:
    """Time the zero-offset and all-perturbation collocation with pyresample's radius neighbour search.

    For each perturbed LOS the ground point is computed and pyresample finds the VIIRS pixels within
    the largest ground radius a cone can reach; the angle test then keeps those in the cone. Returns
    (seconds, FOVs) for *max_granules* CrIS granules, or None when pyresample is not installed.
    """
    try:
        from pyresample import geometry as prgeo
        from pyresample import kd_tree
    except ImportError:
        return None

    g = case.cris[0]
    v = case.viirs[g.key]
    geo = read_file(g.geo, kinds=("cris_geo",))[0]
    vgeo = [read_file(x.geo, kinds=("viirs_geo",))[0] for x in v]
    lat = np.degrees(np.concatenate([x.lat_rad for x in vgeo]))
    lon = np.degrees(np.concatenate([x.lon_rad for x in vgeo]))
    ok = np.isfinite(lat)
    source = prgeo.SwathDefinition(lons=lon[ok], lats=lat[ok])
    t0 = time.perf_counter()
    fg, valid = granule_geometry(geo), geo.valid
    los = perturbed_los_sbf(fg.alpha_rad, fg.beta_rad, offsets_rad(cfg))  # (4,30,9,m,m,3)
    los_e = np.einsum("skfij,skfabj->skfabi", fg.sbf_to_ecef, los)
    sat = np.broadcast_to(fg.sat_ecef_m[..., None, None, :], los_e.shape)
    ground = sat + wgs84.intersect_ellipsoid(sat, los_e)[..., None] * los_e
    glat, glon, _ = wgs84.ecef_to_geodetic(ground.reshape(-1, 3))
    target = prgeo.SwathDefinition(lons=np.degrees(glon), lats=np.degrees(glat))
    radius = float(np.nanmax(np.linalg.norm(ground - sat, axis=-1))) * 0.0085 / 0.5
    with warnings.catch_warnings():  # it warns, rightly, that a cone holds far more than 64 pixels
        warnings.simplefilter("ignore")
        kd_tree.get_neighbour_info(source, target, radius_of_influence=radius, neighbours=64)
    return time.perf_counter() - t0, int(valid.sum())


def _clouds(data: Path) -> str:
    """The simulated case's clouds, as its truth document names them."""
    heights = json.loads((data / "truth.json").read_text()).get("cloud_heights", "ground")
    return "flat clouds" if heights == "ground" else f"clouds with height {heights}"


def run_bench(args: argparse.Namespace, cfg: AssessmentConfig) -> int:
    """``crisgeo bench``: simulate (or take --data), warm the kernels, assess, time each stage, print.

    Parameters
    ----------
    args : argparse.Namespace
        The command's arguments (``--granules``, ``--data``, ``--pyresample``).
    cfg : AssessmentConfig
        The assessment's configuration, on ``cfg.workers`` threads.

    Returns
    -------
    int
        The exit status.
    """
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(args.data) if args.data else Path(tmp)
        t0 = time.perf_counter()
        simulated = not (data / "truth.json").exists()
        if simulated:
            bands = tuple(BANDS) if args.map else ("I5",)
            simulate_case(
                data,
                granules=args.granules,
                profile="paper",
                seed=1,
                cloud_heights=args.clouds,
                viirs_bands=bands,
            )
        t_sim = time.perf_counter() - t0
        t_jit = warm_up()  # numba compiles once (cached on disk); a run pays it once, not per granule
        sim_counted = simulated and not reset_peak_rss()  # the simulation's memory is not the assessment's
        timings = {}
        read0, cpu0, t0 = bytes_read(), time.process_time(), time.perf_counter()
        case = plan([data])
        timings["read"] = time.perf_counter() - t0
        result = assess_plan(case, cfg, timings=timings, workers=cfg.workers)
        wall, cpu, read1 = time.perf_counter() - t0, time.process_time() - cpu0, bytes_read()
        n_cris = len(result.granules)
        n_fov = sum(gr.n_fovs for gr in result.granules)
        print(
            f"case: {n_cris} CrIS granules ({_clouds(data)}), {n_fov} FOVs x {len(offsets_rad(cfg)) ** 2} "
            f"perturbations, cost {cfg.cost}, kernel {cfg.kernel} (simulation {t_sim:.1f} s and kernel "
            f"compile/load {t_jit:.1f} s, not counted)"
        )
        for stage in ("read", "geometry", "parallax", "spectral", "collocation", "cost"):
            t = timings.get(stage, 0.0)
            print(f"  {stage:<12} {t:8.2f} s  {n_fov / t if t else float('inf'):10.0f} FOVs/s")
        print(f"  {'total':<12} {wall:8.2f} s  {n_fov / wall:10.0f} FOVs/s")
        print("(the next granule is read in a thread while one is computed: the stages add up to more)")
        print(f"CPU: {cpu:.1f} CPU-s, {cpu / n_cris:.2f} CPU-s per CrIS granule ({cfg.workers} threads)")
        if read0 is not None and read1 is not None:
            mb = (read1 - read0) / 1e6
            print(f"read: {mb:.0f} MB, {mb / n_cris:.1f} MB per CrIS granule")
        print(f"peak memory: {peak_rss_mb():.0f} MB ({cfg.workers} threads in one process)")
        if sim_counted:
            print("(the main process's peak includes the simulation: this system cannot reset the count)")
        if args.pyresample:
            ref = _pyresample_reference(case, cfg)
            if ref is None:
                print("pyresample reference: not installed (pip install pyresample)")
            else:
                secs, nf = ref
                print(
                    f"pyresample radius search for the same 441 perturbed LOS per FOV, one granule, only the "
                    f"64 nearest pixels (a cone holds 1000-12000) and no angle test or averaging: "
                    f"{secs:.2f} s for {nf} FOVs = {nf / secs:.0f} FOVs/s"
                )
        if args.map:
            _bench_map(data, cpu)
    return 0


def _bench_map(data: Path, assess_cpu_s: float) -> None:
    """Map the case onto every band it holds; print the CPU per band, reading apart, against the
    assessment's."""
    held = tuple(b for b in BANDS if any(data.glob(f"{BANDS[b].sdr_prefix}_*.h5")))
    cpu0 = time.process_time()
    matchup, cost = map_granules([data], held)
    cpu = time.process_time() - cpu0
    n_cris = max(matchup.scans // 4, 1)
    print(f"mapping onto {', '.join(held)}: {n_cris} CrIS granules, {cpu:.1f} CPU-s in all")
    for band in held:
        mb, read_s = cost.bytes_read.get(band, 0) / 1e6, cost.read_s.get(band, 0.0)
        print(
            f"  {band:<4} read {read_s:6.2f} CPU-s ({mb:.0f} MB, {mb / n_cris:.1f} MB per CrIS granule)   "
            f"map {cost.map_s.get(band, 0.0):6.2f} CPU-s"
        )
    read, mapped = sum(cost.read_s.values()), sum(cost.map_s.values())
    print(
        f"  against the assessment's {assess_cpu_s:.1f} CPU-s: {cpu / assess_cpu_s:.2f} with the reading, "
        f"{mapped / assess_cpu_s:.2f} beyond it (reading {read:.1f} CPU-s)"
    )
