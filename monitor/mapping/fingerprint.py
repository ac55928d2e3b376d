"""The daily LOS fingerprint of CrIS geolocation processing, from the GEO files alone.

The LOS of each FOR in the spacecraft body frame, recovered from a granule's own geolocation fields by
the inverse geolocation, is set by the engineering packet's mapping angles. Its per-FOR FOV-5 angles
(alpha in-track, beta cross-track) and the pattern of the 9 FOVs around FOV 5 are therefore a
fingerprint of the EP in force: an upload that changes the mirror angles shows as a step in it, with
no VIIRS data needed.

On the real NOAA-20 granules of 2018-10-22 the FOV-5 angles scatter from scan to scan by <= 2 urad
in-track but 1.5-9.5 urad cross-track depending on the FOR (largest at FOR 1, 11, 21: scene-mirror
servo errors, docs/jpss-formats.md 2.3), and the cross-track angle of those FORs drifts by ~20 urad within
five
minutes. The step threshold of each FOR and direction is therefore set from the measured scatter:
max(10 urad, 4 x the scan-to-scan standard deviation).
"""

from __future__ import annotations

import datetime as dt
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from monitor.core.constants import PROCESSING_CHANGE_URAD, URAD
from monitor.core.errors import DataError
from monitor.geometry.ep_model import FOV5
from monitor.geometry.inverse import granule_geometry
from monitor.mapping.identify import EpMatch, identify_ep
from monitor.sdr import CrisGeoGranule, GranuleError, read_file
from monitor.sdr.engpkt import load_library
from monitor.sdr.names import parse_name
from monitor.sdr.pairing import find_files


@dataclass
class GranulePrint:
    """Per-FOR FOV-5 angles of one granule (urad, means over its scans) and the FOV pattern (30, 9)."""

    granule_id: str
    start: str
    alpha_urad: np.ndarray
    beta_urad: np.ndarray
    pattern_alpha_urad: np.ndarray
    pattern_beta_urad: np.ndarray
    scan_alpha_urad: np.ndarray  # (nscan, 30), for the scatter
    scan_beta_urad: np.ndarray


@dataclass
class DayPrint:
    """The fingerprint of a set of granules: per-FOR means and scan-to-scan scatter (urad)."""

    alpha_urad: np.ndarray
    beta_urad: np.ndarray
    sd_alpha_urad: np.ndarray
    sd_beta_urad: np.ndarray
    pattern_alpha_urad: np.ndarray
    pattern_beta_urad: np.ndarray
    granules: list = field(default_factory=list)

    @classmethod
    def from_dict(cls, d: dict) -> "DayPrint":
        rows = sorted(d["fors"], key=lambda r: r["for"])
        col = lambda k: np.array([r[k] for r in rows], float)  # noqa: E731
        return cls(
            col("alpha_urad"),
            col("beta_urad"),
            col("sd_alpha_urad"),
            col("sd_beta_urad"),
            np.array([r["pattern_alpha_urad"] for r in rows]),
            np.array([r["pattern_beta_urad"] for r in rows]),
            list(d.get("granules", [])),
        )

    def to_dict(self) -> dict:
        return {
            "granules": self.granules,
            "fors": [
                {
                    "for": k + 1,
                    "alpha_urad": float(self.alpha_urad[k]),
                    "beta_urad": float(self.beta_urad[k]),
                    "sd_alpha_urad": float(self.sd_alpha_urad[k]),
                    "sd_beta_urad": float(self.sd_beta_urad[k]),
                    "pattern_alpha_urad": np.round(self.pattern_alpha_urad[k], 2).tolist(),
                    "pattern_beta_urad": np.round(self.pattern_beta_urad[k], 2).tolist(),
                }
                for k in range(len(self.alpha_urad))
            ],
        }


def granule_print(geo: CrisGeoGranule) -> GranulePrint:
    """The fingerprint of one CrIS GEO granule (a :class:`monitor.sdr.CrisGeoGranule`).

    Parameters
    ----------
    geo : CrisGeoGranule
        The granule.

    Returns
    -------
    GranulePrint
        Per FOR the FOV-5 SBF angles' median and per-scan values, urad.
    """
    valid = geo.valid
    fg = granule_geometry(geo)
    a = np.where(valid, fg.alpha_rad, np.nan) / URAD
    b = np.where(valid, fg.beta_rad, np.nan) / URAD
    with np.errstate(all="ignore"):
        return GranulePrint(
            geo.meta.granule_id,
            geo.meta.start.isoformat(),
            np.nanmean(a[:, :, FOV5], axis=0),
            np.nanmean(b[:, :, FOV5], axis=0),
            np.nanmean(a - a[:, :, FOV5 : FOV5 + 1], axis=0),
            np.nanmean(b - b[:, :, FOV5 : FOV5 + 1], axis=0),
            a[:, :, FOV5],
            b[:, :, FOV5],
        )


def day_print(prints: list[GranulePrint]) -> DayPrint:
    """Combine granule fingerprints: medians over granules, scatter over all scans.

    Parameters
    ----------
    prints : list of GranulePrint
        The granules' fingerprints, in time order.

    Returns
    -------
    DayPrint
        Per FOR the median alpha and beta and their scan-to-scan scatter, urad.
    """
    sa = np.concatenate([p.scan_alpha_urad for p in prints])
    sb = np.concatenate([p.scan_beta_urad for p in prints])
    with np.errstate(all="ignore"):
        return DayPrint(
            np.nanmedian([p.alpha_urad for p in prints], axis=0),
            np.nanmedian([p.beta_urad for p in prints], axis=0),
            np.nanstd(sa, axis=0),
            np.nanstd(sb, axis=0),
            np.nanmedian([p.pattern_alpha_urad for p in prints], axis=0),
            np.nanmedian([p.pattern_beta_urad for p in prints], axis=0),
            [p.granule_id for p in prints],
        )


K_SIGMA = 4.0


def thresholds(
    sd_alpha_urad: np.ndarray, sd_beta_urad: np.ndarray, threshold_urad: float = PROCESSING_CHANGE_URAD
) -> tuple[np.ndarray, np.ndarray]:
    """Per-FOR step thresholds (urad): max(threshold, 4 x scan-to-scan scatter), per direction.

    Parameters
    ----------
    sd_alpha_urad, sd_beta_urad : numpy.ndarray
        The scan-to-scan scatter per FOR, urad.
    threshold_urad : float, optional
        The least step of a processing change, urad (``fingerprint.threshold_urad``).

    Returns
    -------
    alpha_urad, beta_urad : numpy.ndarray
        The thresholds per FOR, urad.
    """
    return (
        np.maximum(threshold_urad, K_SIGMA * np.nan_to_num(sd_alpha_urad)),
        np.maximum(threshold_urad, K_SIGMA * np.nan_to_num(sd_beta_urad)),
    )


def _changed_fors(
    before_a: np.ndarray,
    before_b: np.ndarray,
    after_a: np.ndarray,
    after_b: np.ndarray,
    thr_a: np.ndarray,
    thr_b: np.ndarray,
) -> tuple[list[int], np.ndarray, np.ndarray]:
    da, db = after_a - before_a, after_b - before_b
    fors = [k + 1 for k in range(len(da)) if abs(da[k]) > thr_a[k] or abs(db[k]) > thr_b[k]]
    return fors, da, db


def compare_days(
    previous: DayPrint, current: DayPrint, threshold_urad: float = PROCESSING_CHANGE_URAD
) -> tuple[list[int], np.ndarray, np.ndarray]:
    """(FORs changed, d_alpha_urad, d_beta_urad) between two daily fingerprints.

    Thresholds use the larger scatter of the two days: a step between days does not widen either.

    Parameters
    ----------
    previous, current : DayPrint
        The two days' prints.
    threshold_urad : float, optional
        The least step of a processing change, urad (``fingerprint.threshold_urad``).

    Returns
    -------
    fors : list of int
        The FORs changed (1-based).
    d_alpha_urad, d_beta_urad : numpy.ndarray
        The moves per FOR, urad.
    """
    return _changed_fors(
        previous.alpha_urad,
        previous.beta_urad,
        current.alpha_urad,
        current.beta_urad,
        *thresholds(
            np.fmax(previous.sd_alpha_urad, current.sd_alpha_urad),
            np.fmax(previous.sd_beta_urad, current.sd_beta_urad),
            threshold_urad,
        ),
    )


def change_within(
    prints: list[GranulePrint],
    threshold_urad: float = PROCESSING_CHANGE_URAD,
    min_side: int = 2,
    reference: DayPrint | None = None,
) -> tuple[int, list[int], np.ndarray, np.ndarray] | None:
    """The first granule after a step within a time-ordered day, or None.

    For every split with at least *min_side* granules on each side, the granule-median fingerprints
    before and after are compared; the split with the largest step beyond its threshold wins. The
    thresholds come from the scatter of *reference* (the previous day) or, without one, of the whole
    day, so that the scene-mirror servo excursions of the noisy FORs do not pass for a change.
    Returns (index of the first changed granule, FORs changed, d_alpha_urad, d_beta_urad).

    Parameters
    ----------
    prints : list of GranulePrint
        The granules' fingerprints, in time order.
    threshold_urad : float, optional
        The least step of a processing change, urad (``fingerprint.threshold_urad``).
    min_side : int, optional
        The fewest granules on each side of a split.
    reference : DayPrint, optional
        The previous day's print.

    Returns
    -------
    tuple or None
        (index of the first changed granule, FORs changed, d_alpha_urad, d_beta_urad); None without a step.
    """
    ref = reference or day_print(prints)
    thr = thresholds(ref.sd_alpha_urad, ref.sd_beta_urad, threshold_urad)
    a = np.array([p.alpha_urad for p in prints])
    b = np.array([p.beta_urad for p in prints])
    best = None
    for k in range(min_side, len(prints) - min_side + 1):
        fors, da, db = _changed_fors(
            np.nanmedian(a[:k], 0),
            np.nanmedian(b[:k], 0),
            np.nanmedian(a[k:], 0),
            np.nanmedian(b[k:], 0),
            *thr,
        )
        excess = float(np.nanmax(np.concatenate([np.abs(da) / thr[0], np.abs(db) / thr[1]])))
        if fors and (best is None or excess > best[0]):
            best = (excess, k, fors, da, db)
    return None if best is None else best[1:]


@dataclass(frozen=True)
class ProcessingChange:
    """A step in the CrIS geolocation processing seen by the fingerprint: from *time* (ISO 8601 UTC; the
    first changed granule *granule*), at *fors* (1-based), by d_alpha_urad/d_beta_urad per FOR (30,)."""

    time: str
    granule: str
    fors: list
    d_alpha_urad: np.ndarray
    d_beta_urad: np.ndarray

    @property
    def largest_urad(self) -> float:  # numpydoc ignore=RT01
        """The largest change of any FOR in either direction."""
        return float(np.nanmax(np.abs(np.concatenate([self.d_alpha_urad, self.d_beta_urad]))))

    def describe(self, matches: Sequence[EpMatch] = ()) -> str:
        """One sentence for logs, events and messages; with the best-matching EP of *matches* if any.

        Parameters
        ----------
        matches : sequence of EpMatch, optional
            The EP matches; the best one is named.

        Returns
        -------
        str
            The sentence.
        """
        text = (
            f"CrIS geolocation processing changed (LOS fingerprint): FOR {', '.join(map(str, self.fors))}, "
            f"up to {self.largest_urad:.0f} urad, from granule {self.granule}"
        )
        if matches:
            best = matches[0]
            text += f"; best-matching EP {best.name} ({best.version}, rms {best.rms_urad:.0f} urad)"
        return text

    def to_dict(self) -> dict:
        """JSON-ready: time, granule, fors and the per-FOR changes rounded to 0.1 urad.

        Returns
        -------
        dict
            Its JSON.
        """
        return {
            "time": self.time,
            "granule": self.granule,
            "fors": list(self.fors),
            "d_alpha_urad": np.round(self.d_alpha_urad, 1).tolist(),
            "d_beta_urad": np.round(self.d_beta_urad, 1).tolist(),
        }


def detect_change(
    prints: list[GranulePrint],
    threshold_urad: float,
    reference: DayPrint | None = None,
    day: dt.date | None = None,
) -> ProcessingChange | None:
    """The processing change of a day: a step within its time-ordered *prints* (from 4 granules), else a
    step against *reference* (the previous day's print; dated 00:00 UTC of *day*), else None.

    Parameters
    ----------
    prints : list of GranulePrint
        The granules' fingerprints, in time order.
    threshold_urad : float
        The least step of a processing change, urad.
    reference : DayPrint, optional
        The previous day's print.
    day : datetime.date, optional
        The day, for a step against *reference* (dated 00:00 UTC).

    Returns
    -------
    ProcessingChange or None
        The change; None without one.
    """
    if len(prints) >= 4:
        within = change_within(prints, threshold_urad, reference=reference)
        if within is not None:
            k, fors, da, db = within
            return ProcessingChange(prints[k].start, prints[k].granule_id, fors, da, db)
    if reference is not None:
        fors, da, db = compare_days(reference, day_print(prints), threshold_urad)
        if fors:
            when = f"{(day or dt.datetime.fromisoformat(prints[0].start).date()).isoformat()}T00:00:00+00:00"
            return ProcessingChange(when, prints[0].granule_id, fors, da, db)
    return None


@dataclass
class DayVerdict:
    """What one day's GEO files say about CrIS geolocation processing: the day's print, the library EPs
    ranked against it (best first), and the processing change found (within the files or against the
    previous day's print), or None."""

    day: DayPrint
    matches: list[EpMatch]
    change: ProcessingChange | None


@dataclass(frozen=True)
class DayFingerprint:
    """What a day's GEO files say by themselves: their granule *prints* in time order, the day's print, and
    the library EPs ranked against it (best first). Only the comparison with the previous day's print
    (:meth:`verdict`) needs the store, so the daily run computes this before it records anything."""

    prints: tuple[GranulePrint, ...]
    day: DayPrint
    matches: tuple[EpMatch, ...]

    def verdict(
        self, threshold_urad: float, reference: DayPrint | None = None, day: dt.date | None = None
    ) -> DayVerdict:
        """The day's :class:`DayVerdict`: its print, its EP matches and the change found within the files
        or against *reference*, the previous day's print (:func:`detect_change`).

        Parameters
        ----------
        threshold_urad : float
            The least step of a processing change, urad.
        reference : DayPrint, optional
            The previous day's print.
        day : datetime.date, optional
            The day, for a step against *reference* (dated 00:00 UTC).

        Returns
        -------
        DayVerdict
            The verdict.
        """
        change = detect_change(list(self.prints), threshold_urad, reference, day)
        return DayVerdict(self.day, list(self.matches), change)


def fingerprint_day(prints: list[GranulePrint], library: dict, platform: str | None) -> DayFingerprint:
    """The :class:`DayFingerprint` of granule *prints*: the EPs of *library* matched against their day print
    (those of *platform* only, when known).

    Parameters
    ----------
    prints : list of GranulePrint
        The granules' fingerprints, in time order.
    library : dict of str to EngineeringPacket
        The EPs to identify from, by name.
    platform : str or None
        The satellite, when known.

    Returns
    -------
    DayFingerprint
        The day's print and matches.
    """
    prints = sorted(prints, key=lambda p: p.start)
    today = day_print(prints)
    return DayFingerprint(tuple(prints), today, tuple(identify_ep(today, library, platform)))


def day_verdict(
    prints: list[GranulePrint],
    library: dict,
    platform: str | None,
    threshold_urad: float,
    reference: DayPrint | None = None,
    day: dt.date | None = None,
) -> DayVerdict:
    """The fingerprint of a day from its granule *prints*: the day print, the EPs of *library* matched
    against it (those of *platform* only, when known), and the change (:func:`detect_change`). The daily
    run and ``crisgeo fingerprint`` both come here.

    Parameters
    ----------
    prints : list of GranulePrint
        The granules' fingerprints, in time order.
    library : dict of str to EngineeringPacket
        The EPs to identify from, by name.
    platform : str or None
        The satellite, when known.
    threshold_urad : float
        The least step of a processing change, urad.
    reference : DayPrint, optional
        The previous day's print.
    day : datetime.date, optional
        The day, for a step against *reference* (dated 00:00 UTC).

    Returns
    -------
    DayVerdict
        The verdict.
    """
    return fingerprint_day(prints, library, platform).verdict(threshold_urad, reference, day)


@dataclass
class FilesPrint:
    """The fingerprint of a set of GEO files (``crisgeo fingerprint``): the day's verdict, the files that
    could not be read (with the reason), the EP library (name -> EngineeringPacket) and its problems."""

    verdict: DayVerdict
    skipped: list[str]
    library: dict
    problems: list[str]

    def to_dict(self) -> dict:
        """The JSON document of ``crisgeo fingerprint --json``.

        Returns
        -------
        dict
            Its JSON (``crisgeo fingerprint --json``).
        """
        doc = self.verdict.day.to_dict()
        doc["skipped"] = self.skipped
        c = self.verdict.change
        doc["change_within"] = None if c is None else {"first_granule": c.granule, "fors": c.fors}
        doc["ep_match"] = [m.to_dict() for m in self.verdict.matches]
        doc["ep_library_problems"] = self.problems
        return doc


def fingerprint_files(
    paths: Sequence[str | os.PathLike[str]],
    ep_library: Iterable[str | os.PathLike[str]] = (),
    threshold_urad: float = PROCESSING_CHANGE_URAD,
) -> FilesPrint:
    """Fingerprint the CrIS GEO files under *paths*, rank the EPs of *ep_library* (files or directories;
    empty: the packaged real EPs) against it and look for a step within the files. A
    :class:`~monitor.core.errors.DataError` when no file can be read.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
        CrIS GEO files or directories.
    ep_library : iterable of str or os.PathLike, optional
        EP files or directories; empty: the packaged real EPs.
    threshold_urad : float, optional
        The least step of a processing change, urad (``fingerprint.threshold_urad``).

    Returns
    -------
    FilesPrint
        The print, the EP matches, the step found and the files skipped.
    """
    files = find_files(paths)
    prints, skipped = [], []
    for f in files:
        try:
            prints += [granule_print(g) for g in read_file(f, kinds=("cris_geo",))]
        except GranuleError as exc:
            skipped.append(str(exc))
    if not prints:
        raise DataError("no readable CrIS GEO granule" + (f" ({skipped[0]})" if skipped else ""))
    library, problems = load_library(list(ep_library))
    platforms = {p.platform for p in map(parse_name, (f.name for f in files)) if p}
    platform = platforms.pop() if len(platforms) == 1 else None
    return FilesPrint(day_verdict(prints, library, platform, threshold_urad), skipped, library, problems)
