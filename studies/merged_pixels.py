"""What merging uniform VIIRS pixels would buy the cone kernel, and what it would cost the offsets.

The cone kernel's work is one quadratic per pixel, disc and perturbation row (studies/speed-and-memory.md).
Fewer pixels is the largest cut an approximation could make. Here each 2 x 2 quad of a prepared VIIRS granule
(two detectors of one scan, two columns) whose I5 BT, and rendered BT in every view, spans at most
*tolerance* K is replaced by one pixel: at the quad's footprint-weighted centroid, its footprints summed,
its radiance (and each view's) their footprint-weighted mean; the other three are left unusable. A quad
merged never straddles a disc's edge by more than its own size, and where the scene varies by more than the
tolerance nothing is merged.

Each case is assessed with the default configuration at each tolerance (0: the service as it is, through
:class:`monitor.assessment.DayAssessment` with the merge passed as its ``piece_variant``), and a row per
case and tolerance gives the share of quads merged, the collocation's seconds, the errors against the truth
and how far each FOR offset and sigma moved from tolerance 0.

    .venv/bin/python -m studies.merged_pixels CASE_DIR... [--tolerance-k 0 0.3 1] [--workers 2]
        [--rows FILE]
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from benchmarks.provenance import emit
from monitor.assessment import DayAssessment
from monitor.assessment.seam import Variation
from monitor.collocation.collocate import warm_up
from monitor.collocation.swath import SwathPiece
from monitor.config.assessment import AssessmentConfig
from monitor.core.result import AssessmentResult
from monitor.instrument.spectral import BandModel, i5_band
from monitor.sdr.pairing import plan
from studies.lift_decision import case_fields, scores


def _quads(a: np.ndarray) -> np.ndarray:
    """(..., R, C) -> (..., R // 2, C // 2, 4): each 2 x 2 quad's four values (an odd last row or column
    dropped)."""
    r2, c2 = a.shape[-2] // 2 * 2, a.shape[-1] // 2 * 2
    lead = a.shape[:-2]
    q = a[..., :r2, :c2].reshape(*lead, r2 // 2, 2, c2 // 2, 2)
    return np.swapaxes(q, -3, -2).reshape(*lead, r2 // 2, c2 // 2, 4)


def _bt_k(radiance: np.ndarray, band: BandModel) -> np.ndarray:
    """The BT of band radiances, NaN where the radiance is."""
    bt = band.bt_from_radiance(np.nan_to_num(radiance, nan=1.0).ravel()).reshape(radiance.shape)
    return np.where(np.isfinite(radiance), bt, np.nan)


def _spread_k(bt_k: np.ndarray) -> np.ndarray:
    """Each quad's BT range (K); inf where a pixel is unusable."""
    q = _quads(bt_k)
    ok = np.isfinite(q).all(axis=-1)
    safe = np.where(ok[..., None], q, 0.0)
    return np.where(ok, safe.max(axis=-1) - safe.min(axis=-1), np.inf)


class Merged:
    """A ``piece_variant``: each prepared piece with its uniform quads merged (module docstring).

    Parameters
    ----------
    tolerance_k : float
        The widest BT range (K) of a quad merged, in its radiance and every rendered view.
    band : BandModel
        The satellite's I5 band.
    """

    def __init__(self, tolerance_k: float, band: BandModel) -> None:
        self.tolerance_k, self.band = tolerance_k, band
        self.merged = self.quads = 0

    def __call__(self, piece: SwathPiece) -> SwathPiece:
        spread = _spread_k(_bt_k(piece.radiance, self.band))
        if piece.rendered is not None:
            spread = np.maximum(spread, _spread_k(_bt_k(piece.rendered, self.band)).max(axis=0))
        merge = spread <= self.tolerance_k
        self.merged, self.quads = self.merged + int(merge.sum()), self.quads + merge.size
        i, j = np.nonzero(merge)
        r, c = 2 * i, 2 * j
        area = _quads(np.moveaxis(piece.area_vec_m2, -1, 0).astype(np.float64))[:, i, j]  # (3, n, 4)
        weight = np.linalg.norm(area, axis=0)  # each pixel's footprint, m2
        total = weight.sum(axis=-1)

        def mean(a: np.ndarray) -> np.ndarray:
            return (_quads(a.astype(np.float64))[..., i, j, :] * weight).sum(axis=-1) / total

        ecef, area_vec, radiance = piece.ecef_m.copy(), piece.area_vec_m2.copy(), piece.radiance.copy()
        ecef[r, c] = mean(np.moveaxis(piece.ecef_m, -1, 0)).T
        area_vec[r, c] = area.sum(axis=-1).T
        radiance[r, c] = mean(piece.radiance)
        for dr, dc in ((0, 1), (1, 0), (1, 1)):
            radiance[r + dr, c + dc] = np.nan
        rendered = None
        if piece.rendered is not None:
            rendered = piece.rendered.copy()
            rendered[:, r, c] = mean(piece.rendered)
        return replace(piece, ecef_m=ecef, area_vec_m2=area_vec, radiance=radiance, rendered=rendered)


def assessed(case: Path, tolerance_k: float, workers: int) -> tuple[AssessmentResult, float, float]:
    """The case's result with quads merged up to *tolerance_k* (0: none), the share merged and the
    collocation's seconds."""
    satellite = json.loads((case / "truth.json").read_text())["satellite"]
    merged = Merged(tolerance_k, i5_band(satellite))
    timings: dict[str, float] = {}
    with DayAssessment(satellite, AssessmentConfig(), workers, Variation(piece=merged)) as day:
        day.add(plan([case]), timings=timings)
        result = day.result()
    return result, merged.merged / max(merged.quads, 1), timings.get("collocation", float("nan"))


def _moved(result: AssessmentResult, exact: AssessmentResult) -> dict:
    """How far the offsets moved from the exact collocation's, in its sigmas, and the sigmas' ratio."""
    pairs = [(f.d_alpha_urad, f.d_beta_urad, f.sigma_alpha_urad, f.sigma_beta_urad) for f in result.fors]
    base = [(f.d_alpha_urad, f.d_beta_urad, f.sigma_alpha_urad, f.sigma_beta_urad) for f in exact.fors]
    a, b = np.array(pairs, float), np.array(base, float)
    z = np.abs(a[:, :2] - b[:, :2]) / b[:, 2:]
    ratio = a[:, 2:] / b[:, 2:]
    return {
        "moved_max_sigma": np.nanmax(z, axis=0).round(2).tolist(),
        "moved_median_sigma": np.nanmedian(z, axis=0).round(2).tolist(),
        "sigma_ratio_range": [round(float(np.nanmin(ratio)), 2), round(float(np.nanmax(ratio)), 2)],
        "lift_ratio": round(float(result.fors[0].parallax_m_per_k / exact.fors[0].parallax_m_per_k), 3)
        if exact.fors[0].parallax_m_per_k
        else None,
    }


def main(argv: list[str] | None = None) -> int:
    """Print (and append to --rows) one row per case and tolerance."""
    parser = argparse.ArgumentParser(prog="python -m studies.merged_pixels", description=__doc__)
    parser.add_argument("cases", nargs="+", type=Path, help="simulated case directories (with truth.json)")
    parser.add_argument("--tolerance-k", type=float, nargs="+", default=[0.0, 0.3, 1.0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--rows", help="append the rows to this JSON-lines file")
    args = parser.parse_args(argv)
    warm_up()  # the kernels loaded before the first collocation is timed
    for case in args.cases:
        truth = json.loads((case / "truth.json").read_text())
        as_is = assessed(case, 0.0, args.workers)  # the service as it is
        exact = as_is[0]
        for tolerance in sorted(set(args.tolerance_k)):
            result, share, seconds = assessed(case, tolerance, args.workers) if tolerance else as_is
            row = {**case_fields(case, truth), "tolerance_k": tolerance, "quads_merged": round(share, 3)}
            row |= {"collocation_s": round(seconds, 1), "median_sigma_urad": [
                round(float(np.nanmedian([getattr(f, k) for f in result.fors])), 1)
                for k in ("sigma_alpha_urad", "sigma_beta_urad")
            ]}  # fmt: skip
            emit(row | scores(result, truth) | _moved(result, exact), args.rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
