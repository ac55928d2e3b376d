"""How much of the footprint kernel's per-pixel work an exact pruning could save.

    python -m studies.kernel_pruning [--pixels 20000] [--rows FILE]

The kernel (:func:`monitor.collocation.collocate._accumulate`) solves, for every pixel in the tangent box of
a FOV's cones, one quadratic per grid row and disc, the discs largest first, and stops at the first disc the
pixel lies in no cone of. A pixel that lies in every turned disc of a disc size (its angle from the FOV's LOS
plus the grid's reach within the disc), or in none, needs no solve for that disc: an exact kernel could
classify it from one dot product. This counts, for directions spread uniformly over the box of a FOV at
nadir and at the swath's edge (the default 21 x 21 grid, the four discs of the footprint kernel), the share
of pixels in all, some and none of each disc's 441 turned copies, and the solves per pixel the kernel makes
now against those an oracle classification would leave. Printed as JSON rows.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from benchmarks.provenance import commit, emit
from monitor.assessment.inputs import offsets_rad
from monitor.collocation.collocate import ANNULI, box_half_widths_rad, los_ecef
from monitor.config.assessment import AssessmentConfig


def shares(beta_rad: float, pixels: int, seed: int = 0) -> dict:
    """The shares in all/some/none of each disc, and the disc solves per pixel now and with an oracle, for
    a FOV at alpha 0 and *beta_rad*, *pixels* directions uniform in the kernel's tangent box."""
    off = offsets_rad(AssessmentConfig())
    half_a, half_b = box_half_widths_rad(beta_rad, off, ANNULI)  # the kernel's box
    rng = np.random.default_rng(seed)
    a = rng.uniform(-half_a, half_a, pixels)
    b = rng.uniform(beta_rad - half_b, beta_rad + half_b, pixels)
    eye = np.broadcast_to(np.eye(3), (pixels, 3, 3))
    d = los_ecef(eye, a, b)  # directions in SBF
    turn_a, turn_b = np.meshgrid(off, beta_rad + off, indexing="ij")
    cones = los_ecef(np.broadcast_to(np.eye(3), (turn_a.size, 3, 3)), turn_a.ravel(), turn_b.ravel())
    cos = d @ cones.T  # (pixels, 441)
    discs = sorted(ANNULI, reverse=True)  # the kernel's order
    inside = np.stack([cos >= math.cos(r) for r in discs])  # (discs, pixels, 441)
    any_in, all_in = inside.any(-1), inside.all(-1)
    # the kernel evaluates disc k when the pixel lay in some cone of every larger disc
    evaluated = np.vstack([np.ones((1, pixels), bool), np.cumprod(any_in, axis=0)[:-1].astype(bool)])
    some = any_in & ~all_in
    return {
        "commit": commit(),
        "beta_deg": round(math.degrees(beta_rad), 1),
        "grid_reach_mrad": round(float(np.abs(off).max()) * math.sqrt(2) * 1e3, 2),
        "discs_mrad": [round(r * 1e3, 2) for r in discs],
        "all_in": [round(float(x), 3) for x in all_in.mean(1)],
        "some": [round(float(x), 3) for x in some.mean(1)],
        "none": [round(float(x), 3) for x in (~any_in).mean(1)],
        "solves_per_pixel_now": round(float(evaluated.sum(0).mean()), 3),
        "solves_per_pixel_oracle": round(float(some.sum(0).mean()), 3),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--pixels", type=int, default=20000)
    p.add_argument("--rows", help="append the JSON rows here")
    args = p.parse_args()
    for beta_deg in (0.0, 48.0):
        emit(shares(math.radians(beta_deg), args.pixels), args.rows)


if __name__ == "__main__":
    main()
