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

An instrument need not keep to the table. :func:`shape` also reads a named shape stretched (``blurred:0.95``,
5 % narrower) or stretched unequally along two axes (``trapezoid:1.015x0.985@30``: an
:class:`EllipticalResponse`, its first axis 30 deg from the in-track direction). Its width at a level is that
of its azimuthal mean, the profile nested annuli see; each axis' width is checked against the table too.
"""

from __future__ import annotations

import functools
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
RIDGE = 1e-9  # of Q's trace added to its diagonal: neighbouring annuli can be nearly collinear
CONSTRAINT_WEIGHT = 1e8  # lambda^2 against Q's trace: the weights' sum held to 1 within ~1e-8
# The scenes a response is read on: power falling as kappa^-3, a field of sharp edges; the widths read change
# by <= 0.5 % for exponents 2 to 4 (a super-Gaussian 5 % narrower; ~0.3 % for the others)
EDGE_SPECTRUM_EXPONENT = 3.0
KAPPA_RANGE = (20.0, math.pi / 450e-6)  # rad^-1: beyond any cone (50 mrad) to the I-band pixel's Nyquist
SPECTRUM_SAMPLES = 200
PROFILE_SAMPLES = 400
READ_SCALES = np.linspace(0.6, 1.4, 33)  # r50 over the nominal, of the super-Gaussians widths are read from
READ_ORDERS = np.array([3.0, 4, 5, 6, 7, 8, 9, 10, 12, 14, 17, 20, 25, 30])


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
        """The angle beyond which the response is 0.

        Returns
        -------
        float
            rad.
        """
        v = np.asarray(self.response)
        last = int(np.flatnonzero(v > 0).max())
        return float(self.radius_rad[min(last + 1, len(v) - 1)])

    def __call__(self, r_rad: ArrayLike) -> np.ndarray:
        """The response at angles *r_rad* (rad) from the LOS."""
        return np.interp(np.abs(r_rad), self.radius_rad, self.response, right=0.0)

    def full_width_rad(self, level: float) -> float:
        """The full width of the response at a level of its peak: twice the largest radius still at or above
        it.

        Parameters
        ----------
        level : float
            The level, a fraction of the peak (0.5: the half-peak width).

        Returns
        -------
        float
            rad.
        """
        r, v = np.asarray(self.radius_rad), np.asarray(self.response)
        below = np.flatnonzero(v < level)
        if below.size == 0:
            return 2.0 * float(r[-1])
        k = int(below[0])
        # between knot k - 1 (>= level) and knot k (< level), linearly; a drop within one radius (a
        # vertical edge) is at that radius
        frac = (v[k - 1] - level) / (v[k - 1] - v[k]) if v[k - 1] > v[k] else 0.0
        return 2.0 * float(r[k - 1] + frac * (r[k] - r[k - 1]))

    def at(self, x_rad: np.ndarray, y_rad: np.ndarray, turn_rad: float = 0.0) -> np.ndarray:
        """The response at angles from the LOS.

        Parameters
        ----------
        x_rad, y_rad : numpy.ndarray
            Angles from the LOS, in-track and cross-track, rad.
        turn_rad : float, optional
            The field's rotation: nothing changes for a radially symmetric response.

        Returns
        -------
        numpy.ndarray
            Relative response, peak 1.
        """
        return self(np.hypot(x_rad, y_rad))

    def stretched(self, scale: float) -> RadialResponse:
        """The same profile *scale* times as wide.

        Parameters
        ----------
        scale : float
            The stretch.

        Returns
        -------
        RadialResponse
            The stretched profile.
        """
        return RadialResponse(tuple(scale * np.asarray(self.radius_rad)), self.response)

    def within_spec(self) -> list[str]:
        """What of the specification's table this response violates.

        Returns
        -------
        list of str
            One line per violated width; empty within the table.
        """
        return _outside_spec(self.full_width_rad, "")


@dataclass(frozen=True)
class EllipticalResponse:
    """A radial profile stretched by *scale_a* along axis a and *scale_b* along axis b, axis a *angle_rad*
    from the in-track direction (towards cross-track) when the field is not turned: R(r_e) with
    r_e^2 = (u / scale_a)^2 + (v / scale_b)^2 in the axes' frame."""

    radial: RadialResponse
    scale_a: float
    scale_b: float
    angle_rad: float

    def __post_init__(self) -> None:
        if not (self.scale_a > 0 and self.scale_b > 0 and math.isfinite(self.angle_rad)):
            raise ValueError(f"an elliptical response needs positive scales: {self.scale_a}, {self.scale_b}")

    @property
    def reach_rad(self) -> float:
        """The angle beyond which the response is 0 in every direction.

        Returns
        -------
        float
            rad.
        """
        return self.radial.reach_rad * max(self.scale_a, self.scale_b)

    def at(self, x_rad: np.ndarray, y_rad: np.ndarray, turn_rad: float = 0.0) -> np.ndarray:
        """The response at angles from the LOS, the field turned.

        Parameters
        ----------
        x_rad, y_rad : numpy.ndarray
            Angles from the LOS, in-track and cross-track, rad.
        turn_rad : float, optional
            The field's rotation, rad (CrIS's field turns with the scene mirror: by the FOR's scan angle).

        Returns
        -------
        numpy.ndarray
            Relative response, peak 1.
        """
        c, s = math.cos(self.angle_rad + turn_rad), math.sin(self.angle_rad + turn_rad)
        u, v = c * x_rad + s * y_rad, -s * x_rad + c * y_rad
        return self.radial(np.hypot(u / self.scale_a, v / self.scale_b))

    def azimuthal_mean(self) -> RadialResponse:
        """The response averaged over directions at each angle from the LOS: what annuli about it see.

        Returns
        -------
        RadialResponse
            The mean profile.
        """
        r = np.linspace(0.0, self.reach_rad, 4 * KNOTS)
        phi = np.linspace(0.0, 2 * math.pi, 720, endpoint=False)
        v = self.at(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi)).mean(axis=1)
        return RadialResponse(tuple(r), tuple(np.clip(v / v[0], 0.0, 1.0)))

    def full_width_rad(self, level: float) -> float:
        """The full width of the azimuthal mean at a level of its peak.

        Parameters
        ----------
        level : float
            The level, a fraction of the peak (0.5: the half-peak width).

        Returns
        -------
        float
            rad.
        """
        return self.azimuthal_mean().full_width_rad(level)

    def axis_widths_rad(self, level: float) -> tuple[float, float]:
        """The full widths at a level along axes a and b.

        Parameters
        ----------
        level : float
            The level, a fraction of the peak (0.5: the half-peak width).

        Returns
        -------
        width_a_rad, width_b_rad : float
            rad.
        """
        w = self.radial.full_width_rad(level)
        return w * self.scale_a, w * self.scale_b

    def within_spec(self) -> list[str]:
        """What of the specification's table either axis violates.

        Returns
        -------
        list of str
            One line per violated width and axis; empty within the table.
        """
        return [
            *_outside_spec(lambda lv: self.axis_widths_rad(lv)[0], "along axis a "),
            *_outside_spec(lambda lv: self.axis_widths_rad(lv)[1], "along axis b "),
        ]


Response = RadialResponse | EllipticalResponse


def _outside_spec(width_rad: Callable[[float], float], where: str) -> list[str]:
    """The levels of the specification's table at which *width_rad* (level -> full width, rad) is outside."""
    out = []
    for level, lo, hi in SPEC_WIDTHS:
        w = width_rad(level)
        if (lo is not None and w < lo) or (hi is not None and w > hi):
            out.append(f"full width {where}at {100 * level:.0f} % is {math.degrees(w):.4f} deg")
    return out


def _tabulated(profile: Callable[[np.ndarray], np.ndarray], reach_rad: float) -> RadialResponse:
    r = np.linspace(0.0, reach_rad, KNOTS)
    v = np.clip(profile(r), 0.0, 1.0)
    v[0] = 1.0
    v[-1] = 0.0
    return RadialResponse(tuple(r), tuple(v))


def super_gaussian(order: float = 10.0, half_width_50_rad: float = HALF_WIDTH_50_RAD) -> RadialResponse:
    """exp(-ln 2 (r / r50)^order), tabulated out to where it is below 0.1 %.

    Parameters
    ----------
    order : float, optional
        The exponent.
    half_width_50_rad : float, optional
        r50, the half width at half peak, rad.

    Returns
    -------
    RadialResponse
        The profile.
    """
    reach = half_width_50_rad * (math.log(1000.0) / math.log(2.0)) ** (1.0 / order)
    return _tabulated(lambda r: np.exp(-math.log(2.0) * (r / half_width_50_rad) ** order), reach)


def trapezoid(
    inner_rad: float = math.radians(0.391), outer_rad: float = math.radians(0.551)
) -> RadialResponse:
    """1 out to *inner_rad*, linear to 0 at *outer_rad*.

    Parameters
    ----------
    inner_rad, outer_rad : float, optional
        The radii, rad.

    Returns
    -------
    RadialResponse
        The profile.
    """
    return RadialResponse((0.0, inner_rad, outer_rad), (1.0, 1.0, 0.0))


def blurred_top_hat(
    radius_rad: float = math.radians(0.4745), sigma_rad: float = math.radians(0.055)
) -> RadialResponse:
    """A top hat convolved with a circular Gaussian, normalised to its peak.

    Parameters
    ----------
    radius_rad : float, optional
        The top hat's angular radius, rad.
    sigma_rad : float, optional
        The Gaussian's sigma, rad.

    Returns
    -------
    RadialResponse
        The exact 2-D profile, by the Rice integral on a radial grid.
    """
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


def shape(spec: str) -> Response:
    """The response a specification names.

    Parameters
    ----------
    spec : str
        A shape of :data:`SHAPES`, then optionally ``:S`` (stretched S times) or ``:AxB@DEG`` (stretched A
        times along an axis DEG degrees from in-track, B times across it).

    Returns
    -------
    RadialResponse or EllipticalResponse
        The response; a ValueError names what is wrong with *spec*.
    """
    name, _, stretch = spec.partition(":")
    if name not in SHAPES:
        raise ValueError(f"footprint {spec!r}: {name!r} is not one of {', '.join(SHAPES)}")
    base = SHAPES[name]()
    if not stretch:
        return base
    try:
        scales, at, angle = stretch.partition("@")
        a, _, b = scales.partition("x")
        scale_a, scale_b = float(a), float(b or a)
        angle_deg = float(angle) if at else 0.0
    except ValueError:
        raise ValueError(f"footprint {spec!r}: the stretch is S or AxB@DEG, not {stretch!r}") from None
    if not (scale_a > 0 and scale_b > 0):
        raise ValueError(f"footprint {spec!r}: the stretch must be positive")
    if scale_a == scale_b:
        return base.stretched(scale_a)
    return EllipticalResponse(base, scale_a, scale_b, math.radians(angle_deg))


def monotone_weights(m: np.ndarray, radii_rad: tuple[float, ...]) -> np.ndarray:
    """The annulus weights, sum 1, that minimise w^T M w for a response that does not grow outwards.

    Neighbouring annuli see nearly the same scene, so M is nearly singular along differences of their weights,
    and free weights swing from annulus to annulus. A CrIS response is a monotone profile (the specification
    bounds it by widths that grow as the level falls), so the fit keeps it one: the response in annulus k,
    w_k / a_k (a_k its solid angle, ~ r_k^2 - r_(k-1)^2), is a sum of non-negative steps delta_l >= 0 for
    l >= k, w = B delta with B_kl = a_k [l >= k]. With Q = B^T M B = L L^T, the least squares
    ||L^T delta||^2 + lambda^2 (1^T B delta - 1)^2 with delta >= 0 (non-negative least squares, lambda large
    against Q) holds the sum to 1.

    Parameters
    ----------
    m : numpy.ndarray
        M, positive semi-definite, shape (K, K).
    radii_rad : tuple of float
        The annuli's outer radii (the first a disc), rad.

    Returns
    -------
    numpy.ndarray
        The weights, shape (K,).
    """
    from scipy.optimize import nnls  # here: the CLI lists the shapes, and starts without scipy

    r_out = np.asarray(radii_rad, float)
    area = r_out**2 - np.concatenate([[0.0], r_out[:-1]]) ** 2
    k = len(r_out)
    b = area[:, None] * np.triu(np.ones((k, k)))  # w_k = a_k sum_(l >= k) delta_l
    q = b.T @ m @ b
    q = q + RIDGE * np.trace(q) / k * np.eye(k)
    vals, vecs = np.linalg.eigh(q)
    root = vecs * np.sqrt(np.clip(vals, 0.0, None))  # Q = root root^T (a square root where Q is singular)
    total = b.sum(axis=0)  # 1^T B
    lam = np.sqrt(CONSTRAINT_WEIGHT * np.trace(q)) / np.linalg.norm(total)
    delta, _ = nnls(np.vstack([root.T, lam * total]), np.r_[np.zeros(k), lam])
    w = b @ delta
    return w / w.sum()


def seen_weights(profiles: np.ndarray, rho_rad: np.ndarray, radii_rad: tuple[float, ...]) -> np.ndarray:
    """The annulus weights the response fit finds for radial profiles on scenes of sharp edges.

    The fit does not return each annulus' share of the response. It returns the weights whose annulus means
    best reproduce the response-weighted mean over the day's scenes (:func:`monotone_weights`). For a scene L
    with power spectrum P(kappa), isotropic, the mean of the residual's square is, by Parseval,

        E (sum_k w_k A_k - C)^2 = int P(kappa) (sum_k w_k a_k(kappa) - r(kappa))^2 2 pi kappa d kappa,

    with a_k the Fourier transform of annulus k's uniform mean (a disc of radius R: 2 J1(kappa R) / (kappa
    R); an annulus, the difference of its discs weighted by their areas) and r = int R J0(kappa rho) rho d rho
    / int R rho d rho the response's. With sum w = 1 the residual is sum_k w_k (a_k - r), so M is the integral
    of (a_k - r)(a_l - r) P. Scenes of sharp edges (clouds, coasts) have P ~ kappa^-3
    (:data:`EDGE_SPECTRUM_EXPONENT`), out to the VIIRS I-band pixel's Nyquist frequency. Where the response
    falls inside an annulus, its weights fall short of its share there.

    Parameters
    ----------
    profiles : numpy.ndarray
        Radial profiles, shape (S, P).
    rho_rad : numpy.ndarray
        Their angles from the LOS, evenly spaced from 0, rad, shape (P,).
    radii_rad : tuple of float
        The annuli's outer radii, rad.

    Returns
    -------
    numpy.ndarray
        Shape (S, K).
    """
    from scipy.special import j0, j1  # here: the CLI lists the shapes, and starts without scipy

    kappa = np.geomspace(*KAPPA_RANGE, SPECTRUM_SAMPLES)
    measure = np.sqrt(kappa ** (-EDGE_SPECTRUM_EXPONENT) * 2 * math.pi * kappa * np.gradient(kappa))
    r_out = np.asarray(radii_rad, float)
    r_in = np.concatenate([[0.0], r_out[:-1]])

    def disc(radius: np.ndarray) -> np.ndarray:  # (kappa, K) r^2 times the disc's mean's transform
        x = np.outer(kappa, radius)
        return radius**2 * np.divide(2 * j1(x), x, out=np.ones_like(x), where=x > 0)

    a = (disc(r_out) - disc(r_in)) / (r_out**2 - r_in**2)  # (kappa, K)
    kernel = j0(np.outer(kappa, rho_rad)) * rho_rad  # (kappa, P)
    profiles = np.atleast_2d(profiles)
    r = (kernel @ profiles.T) / (profiles @ rho_rad)  # (kappa, S); the spacing cancels
    out = []
    for s in range(profiles.shape[0]):
        e = (a - r[:, s : s + 1]) * measure[:, None]
        out.append(monotone_weights(e.T @ e, radii_rad))
    return np.array(out)


@functools.cache
def _super_gaussians(radii_rad: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The weights (scales, orders, K) :func:`seen_weights` gives for the super-Gaussians of
    :data:`READ_SCALES` x :data:`READ_ORDERS`, and a reader of (scale, log order) from weights."""
    reach = HALF_WIDTH_50_RAD * READ_SCALES[-1] * (math.log(1000.0) / math.log(2.0)) ** (1 / READ_ORDERS[0])
    rho = np.linspace(0.0, reach, PROFILE_SAMPLES)
    s, n = np.meshgrid(READ_SCALES, READ_ORDERS, indexing="ij")
    profiles = np.exp(-math.log(2.0) * (rho / (HALF_WIDTH_50_RAD * s.reshape(-1, 1))) ** n.reshape(-1, 1))
    table = seen_weights(profiles, rho, radii_rad).reshape(*s.shape, len(radii_rad))
    return table, np.log(READ_ORDERS)


def top_hat_weights(radii_rad: tuple[float, ...], radius_rad: float) -> np.ndarray:
    """The annulus weights of a top hat: each annulus' solid angle within it, over the top hat's.

    Parameters
    ----------
    radii_rad : tuple of float
        The annuli's outer radii (the first a disc), rad.
    radius_rad : float, optional
        The top hat's angular radius, rad; the last annulus holds the rest if it reaches past it.

    Returns
    -------
    numpy.ndarray
        Shape (K,).
    """
    r_out = np.asarray(radii_rad, float)
    r_in = np.concatenate([[0.0], r_out[:-1]])
    inside = np.clip(np.minimum(radius_rad, r_out) ** 2 - r_in**2, 0.0, None)
    return inside / inside.sum()


def widths_of_weights(
    radii_rad: tuple[float, ...], weights: np.ndarray, levels: tuple[float, ...] = (0.5, 0.1)
) -> dict[float, float]:
    """The full widths of the response that fitted annulus weights describe.

    The response read is the super-Gaussian exp(-ln 2 (r / r50)^n) whose weights on scenes of sharp edges
    (:func:`seen_weights`) are closest to *weights* in least squares, r50 within :data:`READ_SCALES` of the
    nominal and n within :data:`READ_ORDERS`: the family spans the flat tops and soft edges of every shape
    here.

    Parameters
    ----------
    radii_rad : tuple of float
        The annuli's outer radii (the first a disc), rad.
    weights : numpy.ndarray
        The fitted weights, shape (K,).
    levels : tuple of float, optional
        The levels, fractions of the peak.

    Returns
    -------
    dict of float to float
        Level to full width, rad; NaN where the weights are not a response, or where the closest lies on the
        edge of the scales.
    """
    from scipy.interpolate import RegularGridInterpolator
    from scipy.optimize import least_squares

    w = np.asarray(weights, float)
    if not np.isfinite(w).all() or w[0] <= 0 or np.any(w < -1e-9):
        return dict.fromkeys(levels, float("nan"))
    table, log_orders = _super_gaussians(tuple(radii_rad))
    near = np.unravel_index(np.argmin(((table - w) ** 2).sum(axis=-1)), table.shape[:2])
    seen = RegularGridInterpolator((READ_SCALES, log_orders), table)
    lo, hi = (READ_SCALES[0], log_orders[0]), (READ_SCALES[-1], log_orders[-1])
    fit = least_squares(
        lambda p: seen(p[None, :])[0] - w, [READ_SCALES[near[0]], log_orders[near[1]]], bounds=(lo, hi)
    )
    scale, order = float(fit.x[0]), math.exp(fit.x[1])
    if not READ_SCALES[0] < scale < READ_SCALES[-1]:
        return dict.fromkeys(levels, float("nan"))
    r50 = HALF_WIDTH_50_RAD * scale
    return {level: 2 * r50 * (math.log(1 / level) / math.log(2.0)) ** (1 / order) for level in levels}
