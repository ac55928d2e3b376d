"""How high the day's clouds stand, from the day's own cost: the parallax correction's scale.

The collocation stands every VIIRS pixel kappa (m per K) times how much colder than its clear-sky
neighbourhood it is above its GEO point (:mod:`monitor.collocation.lift`) and renders what each CrIS FOV
row sees of that (:mod:`monitor.collocation.render`). kappa is the inverse of the lapse rate seen
through the window channel; it differs from day to day, region to region, and is zero where the cold scenes
are not high clouds (snow, cold ground, a simulated day whose clouds lie on the ground). So it is not
assumed: the assessment collocates twice, at kappa = 0 (V0, every sample's VIIRS BT at every turn) and at
the probe kappa1 (V1), and for a fraction f

    V(f) = V0 + f (V1 - V0)

is the collocation at kappa = f kappa1 to first order (a lift moves a pixel by a small part of a cone; a cone
mean moves linearly with the pixels that cross its edge). The day's f is where the sum over the FORs, and over
each FOR's three FOV rows (:data:`ROWS`), of their own cost minimum (the configured cost, through the paper's
cone scaled to the width the FOR's response reads, :func:`matched_cone`; the value at the sub-step minimum,
:func:`monitor.estimation.cost.minimum_value`: a grid minimum rises and falls as a row's turn moves between
grid points, and would pull f to where the rows' turns lie on the grid) is least: a wrong scale leaves each
cloud edge turned by an amount that grows with its height, which no single turn of a row can undo. Each row
has its own turn because an error of the EP's FOV positions turns the rows apart, the same for every scene, as
the parallax of one cloud height does: one turn for the whole FOR would take a lift for it
(studies/clouds-with-height.md).
f is searched on :data:`FRACTIONS` and refined by the parabola through the least three; it stays within
them (0 where the cost prefers no lift).

Its uncertainty is derived like the offsets': the delete-one-granule jackknife of f (each replicate searched
again about the day's f; a run of consecutive granules per replicate on a long day,
:func:`monitor.estimation.jackknife.granule_runs`), sigma_f^2 = (G - 1)/G sum (f_g - mean)^2. The lift is kept
(:func:`keeps`) only where it is a height a cloud could have, at least :data:`MIN_LIFT_M_PER_K` (half of
what tops falling at the dry adiabat's 9.8 K/km give, 102 m/K: no elevated cloud's window BT falls faster
with height), and it lowers the day's cost by more than :data:`GAIN_SIGMAS` jackknife sigma of that gain;
else the day is estimated without it (f = 0) and sigma_f is the f declined. With fewer than 3 granules
nothing can be judged: no lift. The size keeps a flat day's hair of preferred lift at none; the gain
declines a lift that a calibration difference or a blur of cold scenes prefers without a height behind it.
sigma_f reaches every offset through that offset's sensitivity to f, by the delta method:
sigma^2 += (dx/df sigma_f)^2, where dx/df is the central difference over +-:data:`SENSITIVITY_STEP` of
that scaled cone's minimum (the FOR's, and each FOV row's for the rows' difference). The rows ahead and
behind move apart by ~230 urad per unit of f, the FOR offsets by far less.


What the rule achieves on simulated and independent days, and where it falls short (a row error on a
cloudy day is partly taken for lift): docs/science.md, "Validation" and "Known limitations".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from monitor.core.constants import FOV_HALF_ANGLE_RAD
from monitor.core.vocabulary import Cost
from monitor.estimation.cost import cost_surface, find_minimum, minimum_value
from monitor.estimation.estimate import (
    FOV_ROWS,
    ForSamples,
    fitted_response,
    through,
)
from monitor.estimation.jackknife import granule_runs, jackknife_sigma
from monitor.instrument.footprint import HALF_WIDTH_50_RAD, top_hat_weights, widths_of_weights

FRACTIONS = np.linspace(0.0, 2.5, 11)
SENSITIVITY_STEP = 0.1
MIN_LIFT_M_PER_K = 50.0  # half the dry adiabat's 102 m/K (9.8 K/km): a smaller law is no cloud's
GAIN_SIGMAS = 1.0  # the day's gain in cost, in its jackknife sigmas, that keeps a lift
ROWS = ((6, 7, 8), (3, 4, 5), (0, 1, 2))  # FOVs 7-9 ahead, 4-6, 1-3 behind


Blend = Callable[[ForSamples, ForSamples, float], ForSamples]
"""What combines a FOR's samples at no lift and at the probe's into those at a fraction of it (:func:`blend`'s
signature): the assessment takes one as an argument, so that a study can thin or weigh the samples."""


def blend(s0: ForSamples, s1: ForSamples, f: float) -> ForSamples:
    """The samples of a FOR collocated at f times the probe's lift, from those at none and at the probe's.

    Parameters
    ----------
    s0, s1 : ForSamples
        The FOR's samples at no lift and at the probe's, the same samples in the same order.
    f : float
        The fraction of the probe's lift.

    Returns
    -------
    ForSamples
        V0 + f (V1 - V0), the same samples in the same order.
    """
    annuli = None
    if s0.annuli_rad is not None and s1.annuli_rad is not None:
        annuli = s0.annuli_rad + f * (s1.annuli_rad - s0.annuli_rad)
    return replace(s0, d_k=s0.d_k + f * (s1.d_k - s0.d_k), annuli_rad=annuli)


def matched_cone(a: ForSamples, b: ForSamples, cost: Cost) -> tuple[ForSamples, ForSamples]:
    """A FOR's samples at no lift and at the probe's, through the paper's cone scaled to the FOR's response.

    The cone is scaled because the paper's cone wants a lift that is not there where the response is
    narrower than it, while the response's own weights read the lift of days with high clouds short
    (studies/footprint.md).

    Parameters
    ----------
    a, b : ForSamples
        The FOR's samples at no lift and at the probe's.
    cost : Cost
        The cost (``assessment.cost``).

    Returns
    -------
    tuple of ForSamples
        Their surfaces through the cone scaled by the half-peak width the FOR's response reads against the
        nominal (the cone's where there are no annuli); float32, no annuli, for the day's search.
    """
    w = fitted_response(a, cost)
    width = np.nan if w is None else widths_of_weights(a.radii_rad, w)[0.5]
    if np.isfinite(width):
        cone = top_hat_weights(a.radii_rad, width / 2 * FOV_HALF_ANGLE_RAD / HALF_WIDTH_50_RAD)
        a, b = through(a, cone), through(b, cone)
    return _compact(a), _compact(b)


def _compact(s: ForSamples) -> ForSamples:
    """*s* with its surface in float32 (BT differences of a few K keep ~1e-6 K) and no annuli."""
    return replace(s, d_k=s.d_k.astype(np.float32), annuli_rad=None)


def day_cost(
    s0: list[ForSamples],
    s1: list[ForSamples],
    f: float,
    cost: Cost,
    without: np.ndarray | None = None,
    minimum: Callable[[np.ndarray], float] = minimum_value,
) -> float:
    """The sum over the FORs and their FOV rows of their cost minimum at a fraction of the probe's lift.

    Parameters
    ----------
    s0, s1 : list of ForSamples
        Each FOR's samples at no lift and at the probe's.
    f : float
        The fraction.
    cost : Cost
        The cost (``assessment.cost``).
    without : numpy.ndarray, optional
        Granules (ids) whose samples are left out (a jackknife replicate).
    minimum : callable, optional
        A row's cost minimum from its surface, K (a study may give ``numpy.nanmin``, the grid's).

    Returns
    -------
    float
        K; rows with fewer than 3 samples are left out (the FOR where the samples do not say their FOV).
    """
    return float(row_costs(s0, s1, f, cost, without, minimum).sum())


def row_costs(
    s0: list[ForSamples],
    s1: list[ForSamples],
    f: float,
    cost: Cost,
    without: np.ndarray | None = None,
    minimum: Callable[[np.ndarray], float] = minimum_value,
) -> np.ndarray:
    """:func:`day_cost` by FOV row (:data:`ROWS`: ahead, centre, behind).

    Parameters
    ----------
    s0, s1 : list of ForSamples
        Each FOR's samples at no lift and at the probe's.
    f : float
        The fraction.
    cost : Cost
        The cost (``assessment.cost``).
    without : numpy.ndarray, optional
        Granules (ids) left out.
    minimum : callable, optional
        A row's cost minimum from its surface, K (:func:`monitor.estimation.cost.minimum_value`).

    Returns
    -------
    numpy.ndarray
        K, shape (3,); a FOR whose samples do not say their FOV counts in the centre.
    """
    total = np.zeros(len(ROWS))
    for a, b in zip(s0, s1, strict=True):
        keep = np.ones(len(a), bool) if without is None else ~np.isin(a.granule, without)
        groups = (
            [(1, keep)]
            if a.fov is None
            else [(r, keep & np.isin(a.fov, fovs)) for r, fovs in enumerate(ROWS)]
        )
        for r, sel in groups:
            if sel.sum() >= 3:
                d = _lifted(a.d_k[sel], b.d_k[sel], f)
                total[r] += float(minimum(cost_surface(d, a.cris_k[sel], cost)))
    return total


def day_fraction(
    s0: list[ForSamples],
    s1: list[ForSamples],
    cost: Cost,
    without: np.ndarray | None = None,
    near: float | None = None,
) -> float:
    """The fraction of the probe's lift at which the day's cost is least.

    Parameters
    ----------
    s0, s1 : list of ForSamples
        Each FOR's samples at no lift and at the probe's.
    cost : Cost
        The cost (``assessment.cost``).
    without : numpy.ndarray, optional
        Granules (ids) left out.
    near : float, optional
        Search only the three of :data:`FRACTIONS`' spacing about it (a jackknife replicate, about the day's).

    Returns
    -------
    float
        The fraction, refined by the parabola through the least three of :data:`FRACTIONS`; its vertex is kept
        between the outer two.
    """
    step = FRACTIONS[1] - FRACTIONS[0]
    grid = FRACTIONS if near is None else near + step * np.array([-1.0, 0.0, 1.0])
    totals = np.array([day_cost(s0, s1, float(f), cost, without) for f in grid])
    i = int(np.clip(np.argmin(totals), 1, len(grid) - 2))
    y0, y1, y2 = totals[i - 1 : i + 2]
    curvature = y0 - 2 * y1 + y2
    # The vertex stays between the parabola's outer points: beyond them it is an extrapolation, and where a
    # replicate's curve is flat about its least point it would throw f anywhere.
    shift = float(np.clip(0.5 * (y0 - y2) / curvature, -1.0, 1.0)) if curvature > 0 else 0.0
    return float(np.clip(grid[i] + shift * step, FRACTIONS[0], FRACTIONS[-1]))


def keeps(lift_m_per_k: float, gain: float, sigma_gain: float) -> bool:
    """Whether the day keeps the lift its cost prefers.

    Parameters
    ----------
    lift_m_per_k : float
        The lift, m per K.
    gain : float
        What it lowers the day's cost by, K.
    sigma_gain : float
        The gain's jackknife sigma, K.

    Returns
    -------
    bool
        The lift is a height a cloud could have (at least :data:`MIN_LIFT_M_PER_K`) and its gain passes
        :data:`GAIN_SIGMAS` times its sigma.
    """
    return lift_m_per_k >= MIN_LIFT_M_PER_K and gain > GAIN_SIGMAS * sigma_gain


def day_lift(
    s0: list[ForSamples], s1: list[ForSamples], cost: Cost, probe_m_per_k: float
) -> tuple[float, float]:
    """The day's fraction of the probe's lift and its jackknife sigma.

    Parameters
    ----------
    s0, s1 : list of ForSamples
        Each FOR's samples at no lift and at the probe's.
    cost : Cost
        The cost (``assessment.cost``).
    probe_m_per_k : float
        The probe's lift, m per K (what *s1* was collocated at).

    Returns
    -------
    f, sigma_f : float
        (0, the f declined) where :func:`keeps` declines it; sigma NaN where it cannot be judged (fewer than 3
        granules).
    """
    f = day_fraction(s0, s1, cost)
    granules = np.unique(np.concatenate([a.granule for a in s0]))
    if len(granules) < 3:
        return 0.0, float("nan")
    runs = granule_runs(granules)
    f_g = np.array([day_fraction(s0, s1, cost, g, near=f) for g in runs])
    gain_g = np.array([day_cost(s0, s1, 0.0, cost, g) - day_cost(s0, s1, f, cost, g) for g in runs])
    sigma_f, sigma_gain = jackknife_sigma(f_g), jackknife_sigma(gain_g)
    if not keeps(f * probe_m_per_k, day_cost(s0, s1, 0.0, cost) - day_cost(s0, s1, f, cost), sigma_gain):
        return 0.0, max(sigma_f, f)
    return f, sigma_f


def _lifted(d0: np.ndarray, d1: np.ndarray, f: float) -> np.ndarray:
    """The surfaces (float64) at fraction *f* of the probe's lift from those at none and at the probe's."""
    d0 = d0.astype(np.float64)
    return d0 + f * (d1 - d0)


def sensitivity(s0: ForSamples, s1: ForSamples, f: float, cost: Cost) -> np.ndarray:
    """The derivative with f of the FOR's top-hat minimum and of its rows ahead minus behind.

    Parameters
    ----------
    s0, s1 : ForSamples
        The FOR's samples at no lift and at the probe's.
    f : float
        The fraction about which to differentiate.
    cost : Cost
        The cost (``assessment.cost``).

    Returns
    -------
    numpy.ndarray
        Steps per unit f, (alpha, beta, rows alpha, rows beta); NaN where a minimum is missing.
    """
    ends = []
    for df in (-SENSITIVITY_STEP, SENSITIVITY_STEP):
        d = _lifted(s0.d_k, s1.d_k, f + df)
        xy = list(find_minimum(cost_surface(d, s0.cris_k, cost))[:2])
        rows = [find_minimum(cost_surface(d[sel], s0.cris_k[sel], cost))[:2] for sel in _row_masks(s0)]
        xy += list(np.subtract(rows[0], rows[1])) if len(rows) == 2 else [np.nan, np.nan]
        ends.append(xy)
    return (np.array(ends[1]) - np.array(ends[0])) / (2 * SENSITIVITY_STEP)


def _row_masks(s: ForSamples) -> list[np.ndarray]:
    """The samples of the rows ahead and behind (:data:`FOV_ROWS`); empty masks with fewer than 3."""
    if s.fov is None:
        return []
    masks = [np.isin(s.fov, fovs) for fovs in FOV_ROWS]
    return masks if all(m.sum() >= 3 for m in masks) else []
