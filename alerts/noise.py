"""The noise of a day's offsets as the jump rule models it, and the step common to a group of FORs.

The history's error per direction (:class:`Noise`): how far the real scatter is from the reported sigmas,
the share of a day's error the FORs have in common, and the day-to-day correlation, fitted from the
differences of consecutive days (:func:`fit_noise`), and as fitted on every day before a date
(:class:`FittedNoise`: what the store keeps per refit date, so a day's evaluation need not read the years
before its replay). The step common to a group of FORs is their
generalised least-squares mean under that correlation (:func:`pooled`). :mod:`alerts.steps` tests steps
with them; :mod:`alerts.effects` measures what a known change did.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from monitor.core.constants import N_FOR

# the groups of FORs pooled: all, the three tens, every 3 adjacent, each alone; (name, 0-based indices)
GROUPS: tuple[tuple[str, tuple[int, ...]], ...] = (
    (("FOR 1-30", tuple(range(N_FOR))),)
    + tuple((f"FOR {i + 1}-{i + 10}", tuple(range(i, i + 10))) for i in range(0, N_FOR, 10))
    + tuple((f"FOR {i + 1}-{i + 3}", (i, i + 1, i + 2)) for i in range(N_FOR - 2))
    + tuple((f"FOR {i + 1}", (i,)) for i in range(N_FOR))
)
MEMBERS = np.array([[k in idx for k in range(N_FOR)] for _, idx in GROUPS], float)  # (groups, N_FOR)
MIN_HISTORY_DAYS = 20  # assessed days the noise is fitted from before anything is tested


@dataclass(frozen=True)
class Noise:
    """The history's error, per direction: *scale* (real scatter over the reported sigma), *shared* (the
    share of the variance common to the FORs of a day), and *lag1* (the day-to-day correlation)."""

    scale: np.ndarray
    shared: np.ndarray
    lag1: float


def _robust_var(x: np.ndarray) -> float:
    """The variance of a normal sample of zero mean, its values winsorised at 3.5 times the scale their
    median absolute value gives: nearly as precise as the plain variance (the rule's thresholds pay for
    the fit's error), while an outlier costs at most 12 / n of it."""
    x = x[np.isfinite(x)]
    if x.size < 5:
        return math.nan
    clip = 3.5 * 1.4826 * float(np.median(np.abs(x)))
    return float(np.mean(np.minimum(x**2, clip**2)))


def fit_noise(ordinal: np.ndarray, y: np.ndarray, s: np.ndarray) -> Noise | None:
    """The :class:`Noise` of the days *ordinal* (T,), values *y* and sigmas *s* (T, N_FOR, C), from the
    differences of consecutive calendar days scaled by their sigmas: their variance is
    lambda^2 (1 - phi), their lag-one correlation -(1 - phi) / 2, and the variance of their mean over the
    FORs of a day lambda^2 (1 - phi) (rho + (1 - rho) / K). None with fewer than MIN_HISTORY_DAYS pairs.

    Parameters
    ----------
    ordinal : numpy.ndarray
        The days' ordinals, shape (T,).
    y : numpy.ndarray
        The values (urad, or K for the bias), shape (T, N_FOR, C).
    s : numpy.ndarray
        Their sigmas, same shape.

    Returns
    -------
    Noise or None
        None with fewer than MIN_HISTORY_DAYS pairs.
    """
    consecutive = np.flatnonzero(np.diff(ordinal) == 1) + 1
    if len(consecutive) < MIN_HISTORY_DAYS:
        return None
    d = (y[consecutive] - y[consecutive - 1]) / np.hypot(s[consecutive], s[consecutive - 1])
    var1 = np.array([_robust_var(d[..., c]) for c in range(d.shape[-1])])  # lambda^2 (1 - phi)
    if not np.all(np.isfinite(var1)) or np.any(var1 <= 0):
        return None
    u = np.clip(d / np.sqrt(var1), -5.0, 5.0)  # a step is one outlier of the differences: clipped
    follows = np.flatnonzero(np.diff(consecutive) == 1) + 1  # difference pairs on consecutive days
    a, b = u[follows], u[follows - 1]
    ok = np.isfinite(a) & np.isfinite(b)
    norm = math.sqrt(np.sum(a[ok] ** 2) * np.sum(b[ok] ** 2)) if ok.any() else 0.0
    corr = float(np.sum(a[ok] * b[ok]) / norm) if norm > 0 else 0.0
    lag1 = float(np.clip(1.0 + 2.0 * corr, 0.0, 0.9))
    k = np.sum(np.isfinite(u), axis=1)  # FORs per day and direction
    with np.errstate(all="ignore"):
        mean = np.nansum(u, axis=1) / k
    ratio = np.array([_robust_var(mean[:, c]) for c in range(u.shape[-1])])
    kc = np.maximum(np.median(k, axis=0), 2)
    shared = np.clip((ratio - 1.0 / kc) / (1.0 - 1.0 / kc), 0.0, 0.95)
    return Noise(np.sqrt(var1 / (1.0 - lag1)), shared, lag1)


@dataclass(frozen=True)
class FittedNoise:
    """The noise fitted on every assessed day before a date: how many days there were, the :class:`Noise`
    (None: too few to fit), and each FOR's usual sigma there (N_FOR, C), below half of which a day's sigma
    is not believed (a day whose sigmas are too small cannot page)."""

    days: int
    noise: Noise | None
    typical: np.ndarray

    def to_dict(self) -> dict:
        """The fit as JSON-serialisable values (what the store keeps).

        Returns
        -------
        dict
            ``days``, ``typical`` and, when fitted, ``scale``, ``shared`` and ``lag1``.
        """
        out: dict = {"days": self.days, "typical": self.typical.tolist()}
        if self.noise is not None:
            out |= {
                "scale": self.noise.scale.tolist(),
                "shared": self.noise.shared.tolist(),
                "lag1": self.noise.lag1,
            }
        return out

    @classmethod
    def from_dict(cls, d: dict) -> FittedNoise:
        """The fit *d* as :meth:`to_dict` wrote it.

        Parameters
        ----------
        d : dict
            The fit's values.

        Returns
        -------
        FittedNoise
            The fit.
        """
        noise = (
            Noise(np.array(d["scale"], float), np.array(d["shared"], float), float(d["lag1"]))
            if "scale" in d
            else None
        )
        return cls(int(d["days"]), noise, np.array(d["typical"], float))


# the noise of every day before an ordinal (see detect): computed from the series given, or kept by the store
FitSource = Callable[[int], FittedNoise]


def fitted_before(ordinal: np.ndarray, y: np.ndarray, s: np.ndarray, before: int) -> FittedNoise:
    """The :class:`FittedNoise` of the days of the series before the ordinal *before*.

    Parameters
    ----------
    ordinal : numpy.ndarray
        The days' ordinals, shape (T,).
    y : numpy.ndarray
        The values (urad, or K for the bias), shape (T, N_FOR, C).
    s : numpy.ndarray
        Their sigmas, same shape.
    before : int
        The first ordinal not fitted.

    Returns
    -------
    FittedNoise
        The fit.
    """
    days = ordinal < before
    typical = _typical(s, days)
    return FittedNoise(int(np.count_nonzero(days)), _floored_fit(ordinal, y, s, days, typical), typical)


def _typical(s: np.ndarray, days: np.ndarray) -> np.ndarray:
    """Each FOR's and direction's median sigma over the *days* (a mask); NaN where none was measured."""
    with warnings.catch_warnings():  # a FOR never measured there: NaN, as meant
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmedian(np.where(days[:, None, None], s, np.nan), axis=0)


def _floored_fit(
    ordinal: np.ndarray, y: np.ndarray, s: np.ndarray, days: np.ndarray, typical: np.ndarray
) -> Noise | None:
    """:func:`alerts.noise.fit_noise` on the *days*, their sigmas floored at half the *typical* ones."""
    return fit_noise(ordinal[days], y[days], np.fmax(s, 0.5 * typical)[days])


def floored_noise(
    ordinal: np.ndarray, y: np.ndarray, s: np.ndarray, days: np.ndarray
) -> tuple[Noise, np.ndarray] | None:
    """The :class:`Noise` fitted on the *days* (a mask) and the sigmas it applies to: a day's sigma is not
    believed below half the FOR's usual one there (a day whose sigmas are too small cannot page). None
    when the noise cannot be fitted (:func:`alerts.noise.fit_noise`).

    Parameters
    ----------
    ordinal : numpy.ndarray
        The days' ordinals, shape (T,).
    y : numpy.ndarray
        The values (urad, or K for the bias), shape (T, N_FOR, C).
    s : numpy.ndarray
        Their sigmas, same shape.
    days : numpy.ndarray
        bool: the days fitted.

    Returns
    -------
    tuple or None
        (Noise, the floored sigmas); None when the noise cannot be fitted.
    """
    typical = _typical(s, days)
    noise = _floored_fit(ordinal, y, s, days, typical)
    return None if noise is None else (noise, np.fmax(s, 0.5 * typical))


def pooled(d: np.ndarray, sigma: np.ndarray, shared: float | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per group (:data:`GROUPS`) the generalised least-squares step common to its FORs and its sigma, from
    per-FOR differences *d* (..., N_FOR) with sigmas *sigma* correlated by *shared* between FORs (NaN: not
    measured). With a = 1 / sigma, f = rho / (1 - rho + n rho) over the n FORs measured and x the group's
    indicator, x^T S^-1 d = (sum_G a^2 d - f sum_G a sum a d) / (1 - rho), x^T S^-1 x likewise (the
    exchangeable correlation's inverse, Sherman-Morrison). Returns (estimate, sigma), (..., groups).

    Parameters
    ----------
    d : numpy.ndarray
        Per-FOR differences, shape (..., N_FOR); NaN: not measured.
    sigma : numpy.ndarray
        Their sigmas.
    shared : float or numpy.ndarray
        Their correlation between FORs.

    Returns
    -------
    step, sigma : numpy.ndarray
        Per group.
    """
    rho = np.asarray(shared, float)
    a = np.where(np.isfinite(d) & np.isfinite(sigma) & (sigma > 0), 1.0 / np.where(sigma > 0, sigma, 1), 0.0)
    dz = np.where(a > 0, d, 0.0)
    n = np.sum(a > 0, axis=-1, keepdims=True)
    f = rho / (1.0 - rho + n * rho)
    total = np.sum(a * dz, axis=-1, keepdims=True)
    a_g = a @ MEMBERS.T
    num = ((a**2 * dz) @ MEMBERS.T - f * a_g * total) / (1.0 - rho)
    den = ((a**2) @ MEMBERS.T - f * a_g**2) / (1.0 - rho)
    measured = (a > 0).astype(float) @ MEMBERS.T >= np.maximum(1.0, 0.5 * MEMBERS.sum(axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        est = np.where(measured & (den > 0), num / den, np.nan)
        sig = np.where(measured & (den > 0), 1.0 / np.sqrt(den), np.nan)
    return est, sig


def ar1_correlation(ordinal: np.ndarray, lag1: float) -> np.ndarray:
    """The AR(1) correlation of days: lag1 ** |days apart|.

    Parameters
    ----------
    ordinal : numpy.ndarray
        The days' ordinals, shape (T,).
    lag1 : float
        The day-to-day correlation.

    Returns
    -------
    numpy.ndarray
        Shape (T, T).
    """
    apart = np.abs(ordinal[:, None] - ordinal[None, :]).astype(float)
    return lag1**apart if lag1 > 0 else (apart == 0).astype(float)


def step_contrast(n_pre: int, n_post: int) -> np.ndarray:
    """Uniform weights of a step: +1/n_post on the days after it, -1/n_pre on the baseline's.

    Parameters
    ----------
    n_pre, n_post : int
        The baseline's days and the days after the split.

    Returns
    -------
    numpy.ndarray
        Shape (n_pre + n_post,).
    """
    return np.r_[np.full(n_pre, -1.0 / n_pre), np.full(n_post, 1.0 / n_post)]
