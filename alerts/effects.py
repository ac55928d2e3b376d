"""What a known change did to the offsets, measured: the team's first question after an EP upload or a VIIRS
LUT change is whether each FOR moved where it was meant to.

For the day *x* that holds one or more known changes (calendar, granule metadata, LOS fingerprint:
:func:`monitor.history.changes.all_changes`), per FOR and direction (in-track alpha, cross-track beta, urad):

* **before** is the inverse-variance mean of the assessed days ``[x - pre_days, x)``, **after** that of
  ``(x, x + post_days]`` (the jump rule's baseline and size windows, ``alerts.pre_days`` and
  ``alerts.post_days``). Neither reaches another change's day, and the change's own day, which holds both
  levels, is in neither.
* Their sigmas are the jump rule's (:mod:`alerts.steps`): the reported sigmas, floored at half their FOR's
  usual one and scaled by the noise fitted on the days before the change, with its day-to-day correlation.
  The **move** (after - before) has the sigma of the two windows' difference. It is converted to km with the
  FOR's km per urad, the ratio of its stored km and urad sigmas (the day's estimate converts both alike).
* A move is **significant** where |move| exceeds ``z_limit`` sigmas: the two-sided limit at which an inert
  change (no move at all) shows a significant FOR-direction somewhere with probability
  ``alerts.false_detection_at_change`` (Sidak over the FOR-directions measured). The move common to all
  FORs, per direction, is the generalised least-squares estimate the rule pools with
  (:func:`alerts.noise.pooled`).
* **predicted**: where the LOS fingerprints on either side of the change each name an EP (the best match of
  the EP library within :data:`EP_MATCH_URAD`) and the two differ, the move the new EP's mapping angles
  predict. The offset is the turn to add to the GEO's line of sight (the export's ``sign_convention``), so
  turning the GEO's FOV-5 line of sight by delta moves the offset by -delta. The EP model's angles are the
  fingerprint's minus the match's residual (:func:`monitor.mapping.fingerprint.identify_ep`). **chi2**
  weighs observed - predicted with the moves' covariance: exchangeable within a direction (the fitted shared
  part rho; Sherman-Morrison, as :func:`alerts.noise.pooled`), so per direction
  (sum z^2 - f (sum z)^2) / (1 - rho), f = rho / (1 - rho + n rho), n the FORs measured; its degrees of
  freedom are the FOR-directions measured.
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from alerts.noise import GROUPS, Noise, floored_noise, pooled
from alerts.rules import GEOLOCATION, watched_series
from alerts.steps import move, window_mean
from monitor.config.alert_settings import RuleSettings
from monitor.core.constants import N_FOR
from monitor.core.tables import Column, text_table
from monitor.history.changes import Change
from monitor.history.records import History

# the best EP match explains a fingerprint to this rms: the right EP leaves ~30 urad on real NOAA-20 data,
# a wrong one hundreds (monitor.mapping.fingerprint.identify_ep)
EP_MATCH_URAD = 100.0
DIRECTIONS = ("in-track", "cross-track")
KM_SIGMAS = ("sigma_in_track_km", "sigma_cross_track_km")


@dataclass(frozen=True)
class ChangeEffect:
    """What the known *changes* of *day* did (module docstring). Arrays are (N_FOR, 2): in-track alpha and
    cross-track beta per FOR, NaN where a window holds no measured day. *before* and *after* are the first
    and last assessed days of each window (None: no day). *noise_fitted* is False where the history before
    the change was too short to fit the noise: the reported sigmas are then taken as they are."""

    day: dt.date
    changes: tuple[Change, ...]
    before: tuple[dt.date, dt.date] | None
    after: tuple[dt.date, dt.date] | None
    before_urad: np.ndarray
    sigma_before_urad: np.ndarray
    after_urad: np.ndarray
    sigma_after_urad: np.ndarray
    move_urad: np.ndarray
    sigma_move_urad: np.ndarray
    move_km: np.ndarray
    sigma_move_km: np.ndarray
    z_limit: float
    common_move_urad: np.ndarray  # (2,): the move common to all FORs, per direction
    sigma_common_move_urad: np.ndarray
    noise_fitted: bool
    ep_before: str | None  # the EP the fingerprint before the change names, if any
    ep_after: str | None
    predicted_urad: np.ndarray | None  # where both EPs are known and differ
    chi2: float
    dof: int

    @property
    def significant(self) -> np.ndarray:  # numpydoc ignore=RT01
        """(N_FOR, 2): where |move| exceeds ``z_limit`` sigmas."""
        with np.errstate(invalid="ignore"):
            return np.abs(self.move_urad) > self.z_limit * self.sigma_move_urad

    @property
    def residual_urad(self) -> np.ndarray | None:  # numpydoc ignore=RT01
        """Observed minus predicted move, (N_FOR, 2), where a prediction exists."""
        return None if self.predicted_urad is None else self.move_urad - self.predicted_urad

    @property
    def p_value(self) -> float:  # numpydoc ignore=RT01
        """The chance of a chi2 this large were the prediction right (NaN: nothing predicted)."""
        return float(stats.chi2.sf(self.chi2, self.dof)) if self.dof else math.nan

    def title(self) -> str:
        """The day, its changes, and the windows.

        Returns
        -------
        str
            The title.
        """
        span = lambda w: f"{w[0]}..{w[1]}" if w else "no day"  # noqa: E731
        return (
            f"{self.day}: "
            + "; ".join(c.label() for c in self.changes)
            + f" (before {span(self.before)}, after {span(self.after)})"
        )

    def summary(self) -> str:
        """One line: the common move per direction, the significant FOR-directions, the prediction's fit.

        Returns
        -------
        str
            The line.
        """
        common = ", ".join(
            f"{d} {m:+.1f} +- {s:.1f} urad"
            for d, m, s in zip(DIRECTIONS, self.common_move_urad, self.sigma_common_move_urad, strict=True)
        )
        n = int(np.count_nonzero(self.significant))
        text = f"all FORs moved {common}; {n} FOR-direction(s) significant (|z| > {self.z_limit:.2f})"
        if not self.noise_fitted:
            text += "; too little history before it to fit the noise: reported sigmas as they are"
        if self.predicted_urad is not None:
            text += (
                f"; EP {self.ep_before} -> {self.ep_after} predicts the move: chi2 {self.chi2:.1f} for "
                f"{self.dof} FOR-directions (p {self.p_value:.3f})"
            )
        return text

    def rows(self) -> list[EffectRow]:
        """A row per FOR and direction measured, for tables.

        Returns
        -------
        list of EffectRow
            The rows.
        """
        pred = self.predicted_urad
        return [
            EffectRow(
                k + 1,
                DIRECTIONS[c],
                self.before_urad[k, c],
                self.sigma_before_urad[k, c],
                self.after_urad[k, c],
                self.sigma_after_urad[k, c],
                self.move_urad[k, c],
                self.sigma_move_urad[k, c],
                self.move_km[k, c],
                self.sigma_move_km[k, c],
                bool(self.significant[k, c]),
                math.nan if pred is None else float(pred[k, c]),
            )
            for c, k in itertools.product(range(2), range(N_FOR))
            if np.isfinite(self.move_urad[k, c])
        ]


@dataclass(frozen=True)
class EffectRow:
    """One FOR and direction of a :class:`ChangeEffect`."""

    for_index: int
    direction: str
    before_urad: float
    sigma_before_urad: float
    after_urad: float
    sigma_after_urad: float
    move_urad: float
    sigma_move_urad: float
    move_km: float
    sigma_move_km: float
    significant: bool
    predicted_urad: float

    @property
    def residual_urad(self) -> float:  # numpydoc ignore=RT01
        """Observed minus predicted move (NaN: nothing predicted)."""
        return self.move_urad - self.predicted_urad


EFFECT_COLUMNS = (
    Column("FOR", "for_index", "d", 3),
    Column("direction", "direction", "", 11, align="<"),
    Column("before", "before_urad", ".1f", 8, "urad"),
    Column("+-", "sigma_before_urad", ".1f", 5),
    Column("after", "after_urad", ".1f", 8, "urad"),
    Column("+-", "sigma_after_urad", ".1f", 5),
    Column("move", "move_urad", "+.1f", 7, "urad"),
    Column("+-", "sigma_move_urad", ".1f", 5),
    Column("move", "move_km", "+.3f", 7, "km"),
    Column("+-", "sigma_move_km", ".3f", 5),
    Column("sig", lambda r: "yes" if r.significant else "", "", 3),
    Column("predicted", "predicted_urad", "+.1f", 9, "urad"),
    Column("obs-pred", "residual_urad", "+.1f", 8, "urad"),
)


def effect_text(effect: ChangeEffect) -> list[str]:
    """The effect as the command line prints it: its title, its summary, and the table (no prediction
    columns where nothing is predicted).

    Parameters
    ----------
    effect : ChangeEffect
        What a change did.

    Returns
    -------
    list of str
        The lines.
    """
    columns = EFFECT_COLUMNS if effect.predicted_urad is not None else EFFECT_COLUMNS[:-2]
    return [effect.title(), "  " + effect.summary(), *text_table(effect.rows(), columns, "  ")]


def change_effects(
    store: History, satellite: str, changes: list[Change], s: RuleSettings
) -> list[ChangeEffect]:
    """The :class:`ChangeEffect` of every day holding known *changes* of *satellite* (time order), measured
    on the stored offsets; days with no assessed day on either side are left out.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    changes : list of Change
        Known changes, in time order.
    s : RuleSettings
        The rules' parameters.

    Returns
    -------
    list of ChangeEffect
        In time order.
    """
    days, y, sig = watched_series(store, satellite, GEOLOCATION)
    if not days:
        return []
    ordinal = np.array([d.toordinal() for d in days])
    by_day: dict[int, list[Change]] = {}
    for c in sorted(changes, key=lambda c: c.time):
        by_day.setdefault(c.time.date().toordinal(), []).append(c)
    change_days = sorted(by_day)
    out = []
    for i, x in enumerate(change_days):
        lo = max(x - s.pre_days, change_days[i - 1] + 1 if i else x - s.pre_days)
        hi = min(x + s.post_days, change_days[i + 1] - 1 if i + 1 < len(change_days) else x + s.post_days)
        fitted = floored_noise(ordinal, y, sig, ordinal < x)
        noise, sigma = fitted if fitted else (Noise(np.ones(2), np.zeros(2), 0.0), sig)
        effect = _measure(store, satellite, ordinal, y, sigma, noise, (lo, x - 1), (x + 1, hi), s)
        if effect is not None:
            out.append(
                ChangeEffect(
                    day=dt.date.fromordinal(x),
                    changes=tuple(by_day[x]),
                    noise_fitted=fitted is not None,
                    **effect,
                )
            )
    return out


def _span(ordinal: np.ndarray, y: np.ndarray, first: int, last: int) -> tuple[dt.date, dt.date] | None:
    """The first and last days in *first*..*last* with anything measured."""
    days = ordinal[(ordinal >= first) & (ordinal <= last) & np.isfinite(y).any(axis=(1, 2))]
    return (dt.date.fromordinal(int(days[0])), dt.date.fromordinal(int(days[-1]))) if days.size else None


def _measure(
    store: History,
    satellite: str,
    ordinal: np.ndarray,
    y: np.ndarray,
    s: np.ndarray,
    noise: Noise,
    before: tuple[int, int],
    after: tuple[int, int],
    rules: RuleSettings,
) -> dict | None:
    """The fields of a :class:`ChangeEffect` but the day and changes, None without days on both sides."""
    span_before, span_after = _span(ordinal, y, *before), _span(ordinal, y, *after)
    if span_before is None or span_after is None:
        return None
    mean_before, sigma_before = window_mean(ordinal, y, s, *before, noise)
    mean_after, sigma_after = window_mean(ordinal, y, s, *after, noise)
    d, sigma_d = move(ordinal, y, s, before, after, noise)
    km_per_urad = _km_per_urad(store, satellite, after)
    measured = int(np.count_nonzero(np.isfinite(d) & np.isfinite(sigma_d)))
    # Sidak: an inert change shows no |z| beyond the limit at any measured FOR-direction with 1 - rate
    tail = 1.0 - (1.0 - rules.false_detection_at_change) ** (1.0 / max(measured, 1))
    common, sigma_common = pooled(d.T, sigma_d.T, noise.shared[:, None])
    everything = [name for name, _ in GROUPS].index(f"FOR 1-{N_FOR}")
    ep_before, ep_after, predicted = _prediction(store, satellite, before, after)
    chi2, dof = (math.nan, 0) if predicted is None else _chi2(d - predicted, sigma_d, noise.shared)
    return {
        "before": span_before,
        "after": span_after,
        "before_urad": mean_before,
        "sigma_before_urad": sigma_before,
        "after_urad": mean_after,
        "sigma_after_urad": sigma_after,
        "move_urad": d,
        "sigma_move_urad": sigma_d,
        "move_km": d * km_per_urad,
        "sigma_move_km": sigma_d * km_per_urad,
        "z_limit": float(stats.norm.isf(tail / 2.0)),
        "common_move_urad": common[:, everything],
        "sigma_common_move_urad": sigma_common[:, everything],
        "ep_before": ep_before,
        "ep_after": ep_after,
        "predicted_urad": predicted,
        "chi2": chi2,
        "dof": dof,
    }


def _km_per_urad(store: History, satellite: str, window: tuple[int, int]) -> np.ndarray:
    """(N_FOR, 2): km on the ground per urad of turn, per FOR and direction, the median over the window's
    days of the ratio of the stored km and urad sigmas."""
    series = store.series(satellite, dt.date.fromordinal(window[0]), dt.date.fromordinal(window[1]))
    km = np.stack([series.values[f] for f in KM_SIGMAS], axis=-1)
    urad = np.stack([series.values[f] for f in GEOLOCATION.sigmas], axis=-1)
    with np.errstate(all="ignore"):
        ratio = np.where(urad > 0, km / urad, np.nan)
        return np.nanmedian(ratio, axis=0) if len(series) else np.full((N_FOR, 2), np.nan)


def _ep(body: dict | None) -> tuple[str, np.ndarray] | None:
    """The EP a stored fingerprint names (its best match within EP_MATCH_URAD) and that EP's model FOV-5
    angles (N_FOR, 2) urad: the fingerprint's angles minus the match's residual."""
    matches = (body or {}).get("ep_match") or []
    if not matches or not matches[0].get("rms_urad", math.inf) <= EP_MATCH_URAD:
        return None
    best = matches[0]
    rows = sorted(body["fors"], key=lambda r: r["for"]) if body else []
    seen = np.array([[r["alpha_urad"], r["beta_urad"]] for r in rows], float)
    residual = np.array([best["d_alpha_urad"], best["d_beta_urad"]], float).T
    return f"{best['name']} ({best['version']})", seen - residual


def _prediction(
    store: History, satellite: str, before: tuple[int, int], after: tuple[int, int]
) -> tuple[str | None, str | None, np.ndarray | None]:
    """The EPs named before and after, and the offsets' move their mapping angles predict (None unless both
    are named and differ)."""
    prior = store.fingerprint(satellite, dt.date.fromordinal(before[1] + 1))
    later = store.fingerprint(satellite, dt.date.fromordinal(after[1] + 1))
    if later is not None and later[0] < dt.date.fromordinal(after[0]):
        later = None  # the latest print is from before the change
    old, new = _ep(prior[1] if prior else None), _ep(later[1] if later else None)
    name_old, name_new = (old[0] if old else None), (new[0] if new else None)
    if old is None or new is None or name_old == name_new:
        return name_old, name_new, None
    # the GEO's LOS turned by delta: the offset moves by -delta (+ 0.0: no negative zeros in the tables)
    return name_old, name_new, old[1] - new[1] + 0.0


def _chi2(residual: np.ndarray, sigma: np.ndarray, shared: np.ndarray) -> tuple[float, int]:
    """r^T C^-1 r over the FOR-directions measured, C exchangeable within a direction (module docstring),
    and the count of those FOR-directions."""
    total, dof = 0.0, 0
    for c in range(residual.shape[1]):
        ok = np.isfinite(residual[:, c]) & np.isfinite(sigma[:, c]) & (sigma[:, c] > 0)
        z = residual[ok, c] / sigma[ok, c]
        n, rho = z.size, float(shared[c])
        f = rho / (1.0 - rho + n * rho) if n else 0.0
        total += float((np.sum(z**2) - f * np.sum(z) ** 2) / (1.0 - rho))
        dof += n
    return total, dof
