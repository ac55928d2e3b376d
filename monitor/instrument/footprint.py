"""The CrIS FOV's spatial response: a radially symmetric profile of angle from the LOS.

A CrIS FOV does not see the scene through a top-hat cone. The specification (Wang's slides, table 3) bounds
the response by its full widths at four levels of its peak:

    70 % > 0.8735 deg,   50 % = 0.942 deg,   10 % < 1.100 deg,   3 % < 1.238 deg.

A :class:`RadialResponse` is a profile R(r) of the angle r (rad) from the LOS, peak 1, linear between its
knots and 0 beyond the last. The simulator weights the scene by it (:mod:`monitor.simulate.case`); the
assessment does not assume one: it fits the profile over annuli (:mod:`monitor.estimation.estimate`) and
reports the widths it finds (:meth:`RadialResponse.full_width_rad`, :func:`widths_of_weights`).

Named shapes (:data:`SHAPES`), each within the table (``tests/instrument/test_footprint.py`` checks them):
``super-gaussian`` (the default: exp(-ln 2 (r / r50)^10)), ``trapezoid`` (flat to 0.391 deg, linear to 0
at 0.551 deg), ``blurred`` (a 0.949 deg top hat convolved with a Gaussian of sigma 0.055 deg: 0.942 deg at
half peak) and ``top-hat`` (the paper's 0.963 deg cone, which the table does not allow: 100 % to its edge).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.constants import FOV_HALF_ANGLE_RAD

# The specification's full widths (rad) at these levels of the peak: (level, lower bound, upper bound)
SPEC_WIDTHS = (
    (0.70, math.radians(0.8735), None),
    (0.50, math.radians(0.942) * 0.995, math.radians(0.942) * 1.005),  # "= 0.942", stated to 3 digits
    (0.10, None, math.radians(1.100)),
    (0.03, None, math.radians(1.238)),
)
HALF_WIDTH_50_RAD = math.radians(0.942) / 2  # where every shape of the table is at half its peak
KNOTS = 64  # knots of the tabulated smooth shapes


@dataclass(frozen=True)
class RadialResponse:
    """Relative response (peak 1) at angles *radius_rad* from the LOS (increasing, the first 0), linear
    between knots and 0 beyond the last."""

    radius_rad: tuple[float, ...]
    response: tuple[float, ...]

    def __post_init__(self) -> None:
        r, v = np.asarray(self.radius_rad, float), np.asarray(self.response, float)
        if r.ndim != 1 or r.shape != v.shape or len(r) < 2:
            raise ValueError("a radial response needs as many responses as radii, at least two")
        if r[0] != 0.0 or np.any(np.diff(r) < 0) or not np.all(np.isfinite(r)):
            raise ValueError(f"radii must start at 0 and increase: {list(r)}")
        if v[0] != 1.0 or np.any(v < 0) or np.any(v > 1) or not np.all(np.isfinite(v)):
            raise ValueError(f"responses must be 1 at the centre and within 0..1: {list(v)}")

    @property
    def reach_rad(self) -> float:
        """The angle beyond which the response is 0."""
        v = np.asarray(self.response)
        last = int(np.flatnonzero(v > 0).max())
        return float(self.radius_rad[min(last + 1, len(v) - 1)])

    def __call__(self, r_rad: ArrayLike) -> np.ndarray:
        """The response at angles *r_rad* (rad) from the LOS."""
        return np.interp(np.abs(r_rad), self.radius_rad, self.response, right=0.0)

    def full_width_rad(self, level: float) -> float:
        """The full width (rad) of the response at *level* of its peak: twice the largest radius where the
        response is still at or above it."""
        r, v = np.asarray(self.radius_rad), np.asarray(self.response)
        below = np.flatnonzero(v < level)
        if below.size == 0:
            return 2.0 * float(r[-1])
        k = int(below[0])
        # between knot k - 1 (>= level) and knot k (< level), linearly; a drop within one radius (a
        # vertical edge) is at that radius
        frac = (v[k - 1] - level) / (v[k - 1] - v[k]) if v[k - 1] > v[k] else 0.0
        return 2.0 * float(r[k - 1] + frac * (r[k] - r[k - 1]))

    def within_spec(self) -> list[str]:
        """What of the specification's table this response violates (empty: within it)."""
        out = []
        for level, lo, hi in SPEC_WIDTHS:
            w = self.full_width_rad(level)
            if (lo is not None and w < lo) or (hi is not None and w > hi):
                out.append(f"full width at {100 * level:.0f} % is {math.degrees(w):.4f} deg")
        return out


def _tabulated(profile: Callable[[np.ndarray], np.ndarray], reach_rad: float) -> RadialResponse:
    r = np.linspace(0.0, reach_rad, KNOTS)
    v = np.clip(profile(r), 0.0, 1.0)
    v[0] = 1.0
    v[-1] = 0.0
    return RadialResponse(tuple(r), tuple(v))


def super_gaussian(order: float = 10.0, half_width_50_rad: float = HALF_WIDTH_50_RAD) -> RadialResponse:
    """exp(-ln 2 (r / r50)^order), tabulated out to where it is below 0.1 %."""
    reach = half_width_50_rad * (math.log(1000.0) / math.log(2.0)) ** (1.0 / order)
    return _tabulated(lambda r: np.exp(-math.log(2.0) * (r / half_width_50_rad) ** order), reach)


def trapezoid(
    inner_rad: float = math.radians(0.391), outer_rad: float = math.radians(0.551)
) -> RadialResponse:
    """1 out to *inner_rad*, linear to 0 at *outer_rad*."""
    return RadialResponse((0.0, inner_rad, outer_rad), (1.0, 1.0, 0.0))


def blurred_top_hat(
    radius_rad: float = math.radians(0.4745), sigma_rad: float = math.radians(0.055)
) -> RadialResponse:
    """A top hat of angular radius *radius_rad* convolved with a circular Gaussian of *sigma_rad*
    (the exact 2-D profile, by the Rice integral on a radial grid), normalised to its peak."""
    from scipy.special import i0e  # here: the CLI lists the shapes, and starts without scipy

    reach = radius_rad + 4.0 * sigma_rad
    r = np.linspace(0.0, reach, KNOTS)
    # R(r) = int_0^a rho/s^2 exp(-(r^2 + rho^2) / 2 s^2) I0(r rho / s^2) d rho (the Rice distribution's CDF
    # complement); with I0(x) = i0e(x) e^x the exponent is -(r - rho)^2 / 2 s^2 and stays finite
    rho = np.linspace(0.0, radius_rad, 2001)[None, :]
    rr = r[:, None]
    s2 = sigma_rad**2
    integrand = rho / s2 * np.exp(-((rr - rho) ** 2) / (2 * s2)) * i0e(rr * rho / s2)
    v = np.trapezoid(integrand, rho[0], axis=1)
    return _tabulated(lambda x: np.interp(x, r, v / v[0]), reach)


TOP_HAT = RadialResponse((0.0, FOV_HALF_ANGLE_RAD, FOV_HALF_ANGLE_RAD), (1.0, 1.0, 0.0))
SHAPES = {
    "super-gaussian": super_gaussian,
    "trapezoid": trapezoid,
    "blurred": blurred_top_hat,
    "top-hat": lambda: TOP_HAT,
}
DEFAULT_SHAPE = "super-gaussian"


def shape(name: str) -> RadialResponse:
    """The named shape of :data:`SHAPES`."""
    try:
        return SHAPES[name]()
    except KeyError:
        raise ValueError(f"footprint {name!r} is not one of {', '.join(SHAPES)}") from None


def widths_of_weights(
    radii_rad: tuple[float, ...], weights: np.ndarray, levels: tuple[float, ...] = (0.5, 0.1)
) -> dict[float, float]:
    """Full widths (rad) at *levels* of the profile that fitted annulus weights describe.

    *radii_rad* (K,) are the annuli's outer radii (the first annulus a disc), *weights* (K,) the share of the
    response-weighted mean each annulus carries; the response in an annulus is its weight over its solid
    angle (~ pi (r_out^2 - r_in^2)), taken at the annulus' mid radius, relative to the first annulus."""
    r_out = np.asarray(radii_rad, float)
    r_in = np.concatenate([[0.0], r_out[:-1]])
    density = np.asarray(weights, float) / (r_out**2 - r_in**2)
    if not np.isfinite(density).all() or density[0] <= 0:
        return dict.fromkeys(levels, float("nan"))
    profile = RadialResponse(
        (0.0, *((r_in[1:] + r_out[1:]) / 2), float(r_out[-1])),
        (1.0, *np.clip(density[1:] / density[0], 0.0, 1.0), 0.0),
    )
    return {level: profile.full_width_rad(level) for level in levels}
