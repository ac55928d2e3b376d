"""The typed result where the science hands over to the service: per-FOR LOS offsets of one assessment."""

from __future__ import annotations

import json
import math
import typing
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field, fields

import numpy as np

from monitor.core.band_records import DifferenceMap, ForReplicates, RadiometryBin
from monitor.core.constants import DEFAULT_HALF_STEPS, DEFAULT_STEP_URAD, FOV_DIAMETER_URAD
from monitor.core.measures import (
    CALIBRATION_BIAS,
    CALIBRATION_GAIN,
    FOV_ROWS,
    NAN,
    OFFSET_METERS,
    OFFSET_RADIANS,
    RESPONSE_WIDTH,
    SIGMA,
    Measure,
    difference_of,
    difference_sigma_of,
    measured,
)
from monitor.core.vocabulary import DayStop, Decision

FLAG_FEW_SAMPLES = "few_samples"  # fewer FOVs than the minimum: no estimate worth trusting
FLAG_EDGE = "edge"  # the grid minimum is on the border of the perturbation grid
FLAG_FLAT = "flat"  # the cost surface has no clear minimum (uniform scenes carry no information)
FLAG_UNCERTAIN = "uncertain"  # the jackknife spread of the offset exceeds the configured limit
RELIABILITY_FLAGS = (FLAG_FEW_SAMPLES, FLAG_EDGE, FLAG_FLAT, FLAG_UNCERTAIN)
# how the estimate was made, where it is not the configured way (the offset stays usable, its sigma is the
# kernel's that was used): said in the flags, stored and shown, never silent
FLAG_TOP_HAT = "top_hat"  # too few FOVs to fit the footprint: the top-hat cone's estimate and floor
FLAG_UNCONVERGED = "unconverged"  # the footprint's alternation ran out of iterations or windows
# the day's uniform scenes span too little BT to determine a CrIS-VIIRS gain: gain and curvature empty, the
# bias the scenes' mean difference (monitor/estimation/intercal.py)
FLAG_GAIN_UNDETERMINED = "gain_undetermined"
# the offsets read in M15 differ from I5's by more than 3 sigmas of their paired difference: a VIIRS
# band-to-band or geolocation-product matter, not CrIS's (the I5 offset stays usable)
FLAG_BANDS_DIFFER = "bands_differ"
# every flag a FOR may carry, in the order of their bits in the export (the reliability flags first; a new
# flag takes the next bit)
FLAGS = (*RELIABILITY_FLAGS, FLAG_TOP_HAT, FLAG_UNCONVERGED, FLAG_GAIN_UNDETERMINED, FLAG_BANDS_DIFFER)
SECOND_BAND = "M15"  # the band the geolocation is read in besides I5, where assessment.bands lists it


@dataclass(frozen=True)
class SpecBreach:
    """One direction of a FOR beyond the geolocation specification: *direction* ``in-track`` or
    ``cross-track``, the error and its sigma on the ground (km), the specification (km)."""

    direction: str
    error_km: float
    sigma_km: float
    spec_km: float

    @property
    def beyond_doubt(self) -> bool:  # numpydoc ignore=RT01
        """The breach holds beyond the uncertainty: |error| - 2 sigma is still beyond the specification."""
        return math.isfinite(self.sigma_km) and abs(self.error_km) - 2 * self.sigma_km > self.spec_km


@dataclass(frozen=True)
class ForOffset:
    """Offsets of one scan position (FOR 1..30): the turn to apply to the CrIS LOS to best match VIIRS.

    Angles in microradians (in-track alpha, cross-track beta), distances in km on the ground (in-track
    positive along the flight direction, cross-track positive to the right), cost in kelvin. At the optimum,
    the CrIS-VIIRS intercalibration (:mod:`monitor.estimation.intercal`) and the full widths of the CrIS
    spatial response found there (:mod:`monitor.estimation.estimate`), NaN where none was fitted. Every
    measured field is declared once, here, with its unit and meaning (:func:`measured`).
    """

    for_index: int
    d_alpha_urad: float = measured(
        "urad", "in-track LOS offset (see sign_convention)", metric=(OFFSET_RADIANS, "alpha")
    )
    d_beta_urad: float = measured(
        "urad", "cross-track LOS offset (see sign_convention)", metric=(OFFSET_RADIANS, "beta")
    )
    sigma_alpha_urad: float = measured("urad", f"{SIGMA} in-track offset", quality=True)
    sigma_beta_urad: float = measured("urad", f"{SIGMA} cross-track offset", quality=True)
    in_track_km: float = measured(
        "km",
        "in-track geolocation error on the ground (see sign_convention)",
        metric=(OFFSET_METERS, "in_track"),
    )
    cross_track_km: float = measured(
        "km",
        "cross-track geolocation error on the ground (see sign_convention)",
        metric=(OFFSET_METERS, "cross_track"),
    )
    total_km: float = measured("km", "total geolocation error on the ground", metric=(OFFSET_METERS, "total"))
    sigma_in_track_km: float = measured("km", f"{SIGMA} in-track error", quality=True, series=False)
    sigma_cross_track_km: float = measured("km", f"{SIGMA} cross-track error", quality=True, series=False)
    n_samples: int = measured("1", "CrIS FOVs in the cost function", quality=True)
    cost_min_k: float = measured(
        "K",
        "minimum over the perturbations of the cost (STDEV of BT_VIIRS - BT_CrIS, or its residual after the "
        "calibration regression: assessment.cost)",
        quality=True,
    )
    cost_zero_k: float = measured("K", "cost of the unperturbed LOS", quality=True)
    flags: tuple = ()
    bias_k: float = measured(
        "K",
        "CrIS minus VIIRS I5 brightness temperature at 280 K, at the optimum",
        NAN,
        metric=(CALIBRATION_BIAS, ""),
    )
    sigma_bias_k: float = measured("K", f"{SIGMA} CrIS minus VIIRS bias", NAN, quality=True)
    gain_pct: float = measured(
        "percent",
        "CrIS minus VIIRS I5 gain difference (per cent of the BT departure from 280 K)",
        NAN,
        metric=(CALIBRATION_GAIN, ""),
    )
    sigma_gain_pct: float = measured("percent", f"{SIGMA} gain difference", NAN, quality=True)
    curvature_k: float = measured("K", "curvature of CrIS minus VIIRS: what it adds at 250 and 310 K", NAN)
    sigma_curvature_k: float = measured("K", f"{SIGMA} curvature", NAN, quality=True)
    response_width_50_urad: float = measured(
        "urad",
        "full width at 50 % of its peak of the CrIS FOV spatial response fitted at the optimum",
        NAN,
        metric=(RESPONSE_WIDTH, "0.5"),
    )
    sigma_response_width_50_urad: float = measured(
        "urad", f"{SIGMA} response's full width at 50 %", NAN, quality=True
    )
    response_width_10_urad: float = measured(
        "urad",
        "full width at 10 % of its peak of the CrIS FOV spatial response fitted at the optimum",
        NAN,
        metric=(RESPONSE_WIDTH, "0.1"),
    )
    sigma_response_width_10_urad: float = measured(
        "urad", f"{SIGMA} response's full width at 10 %", NAN, quality=True
    )
    # the FOV rows: the offset of the rows ahead (FOVs 7-9) minus that of the rows behind (FOVs 1-3), each
    # estimated alone (monitor.estimation.estimate): parallax of high clouds, or an error of the EP's FOV
    # positions
    fov_rows_alpha_urad: float = measured(
        "urad", "in-track offset of the FOV rows ahead (FOVs 7-9) minus the rows behind (1-3)", NAN,
        metric=(FOV_ROWS, "alpha"),
    )  # fmt: skip
    fov_rows_beta_urad: float = measured(
        "urad", "cross-track offset of the FOV rows ahead (FOVs 7-9) minus the rows behind (1-3)", NAN,
        metric=(FOV_ROWS, "beta"),
    )  # fmt: skip
    sigma_fov_rows_alpha_urad: float = measured("urad", f"{SIGMA} rows' in-track offset", NAN, quality=True)
    sigma_fov_rows_beta_urad: float = measured("urad", f"{SIGMA} rows' cross-track offset", NAN, quality=True)
    parallax_m_per_k: float = measured(
        "m K-1", "height the parallax correction gave a VIIRS pixel per K colder than its clear-sky "
        "neighbourhood (the day's, chosen by the cost; 0: none; NaN: not collocated here)", NAN,
        quality=True, series=False,
    )  # fmt: skip
    parallax_height_km: float = measured(
        "km", "height the parallax correction put the FOR's cold scenes at: its lift per K times its "
        "CrIS BT's 95th minus 5th percentile", NAN, quality=True,
    )  # fmt: skip

    # CrIS minus VIIRS per band over the FOVs uniform in VIIRS (monitor.matchup.radiometry); NaN in a band
    # not configured (assessment.bands)
    cris_minus_viirs_k_I5: float = difference_of("I5")
    sigma_cris_minus_viirs_k_I5: float = difference_sigma_of("I5")
    cris_minus_viirs_k_M13: float = difference_of("M13")
    sigma_cris_minus_viirs_k_M13: float = difference_sigma_of("M13")
    cris_minus_viirs_k_M15: float = difference_of("M15")
    sigma_cris_minus_viirs_k_M15: float = difference_sigma_of("M15")
    cris_minus_viirs_k_M16: float = difference_of("M16")
    sigma_cris_minus_viirs_k_M16: float = difference_sigma_of("M16")

    # the offsets assessed in M15 as in I5 (on the M grid), where assessment.bands lists M15, and M15 minus
    # I5 with the sigma of their paired jackknife replicates (the same granules leave out both)
    d_alpha_urad_M15: float = measured("urad", "in-track LOS offset assessed in VIIRS M15", NAN)
    d_beta_urad_M15: float = measured("urad", "cross-track LOS offset assessed in VIIRS M15", NAN)
    sigma_alpha_urad_M15: float = measured("urad", f"{SIGMA} in-track offset in M15", NAN, quality=True)
    sigma_beta_urad_M15: float = measured("urad", f"{SIGMA} cross-track offset in M15", NAN, quality=True)
    m15_minus_i5_alpha_urad: float = measured("urad", "in-track LOS offset in M15 minus that in I5", NAN)
    m15_minus_i5_beta_urad: float = measured("urad", "cross-track LOS offset in M15 minus that in I5", NAN)
    sigma_m15_minus_i5_alpha_urad: float = measured(
        "urad", f"{SIGMA} in-track M15 minus I5", NAN, quality=True
    )
    sigma_m15_minus_i5_beta_urad: float = measured(
        "urad", f"{SIGMA} cross-track M15 minus I5", NAN, quality=True
    )

    @property
    def scan_position(self) -> int:  # numpydoc ignore=RT01
        """The field of regard, 1..30 across the scan (the name the JSON, the export and the manual use)."""
        return self.for_index

    @property
    def d_alpha_pct_fov(self) -> float:  # numpydoc ignore=RT01
        """The in-track offset as a percentage of the FOV diameter."""
        return 100.0 * self.d_alpha_urad / FOV_DIAMETER_URAD

    @property
    def d_beta_pct_fov(self) -> float:  # numpydoc ignore=RT01
        """The cross-track offset as a percentage of the FOV diameter."""
        return 100.0 * self.d_beta_urad / FOV_DIAMETER_URAD

    @property
    def reliable(self) -> bool:  # numpydoc ignore=RT01
        """Whether no flag of RELIABILITY_FLAGS is set: the offset may be trusted and alerted on."""
        return not any(f in RELIABILITY_FLAGS for f in self.flags)

    @property
    def worst_km(self) -> float:  # numpydoc ignore=RT01
        """The larger of the in-track and cross-track errors on the ground, in magnitude (km): what the
        specification judges (:meth:`spec_breaches`); NaN when neither was measured. "Worst" on every
        surface is this; the total (their root sum of squares) is shown as the total, never judged."""
        errors = [abs(e) for e in (self.in_track_km, self.cross_track_km) if math.isfinite(e)]
        return max(errors) if errors else math.nan

    def spec_breaches(self, spec_km: float) -> tuple[SpecBreach, ...]:
        """The one definition of "out of spec".

        A reliable FOR is out of spec when its in-track or cross-track error on the ground exceeds the
        specification, each direction on its own (the specification is per direction, as the paper plots it;
        the total is shown, never judged).

        Parameters
        ----------
        spec_km : float
            The specification, km (``alerts.spec_km``).

        Returns
        -------
        tuple of SpecBreach
            One per direction whose error on the ground exceeds *spec_km* in magnitude; empty when within it,
            and for an unreliable FOR (no trustworthy number to judge).
        """
        if not self.reliable:
            return ()
        return tuple(
            SpecBreach(direction, error_km, sigma_km, spec_km)
            for direction, error_km, sigma_km in (
                ("in-track", self.in_track_km, self.sigma_in_track_km),
                ("cross-track", self.cross_track_km, self.sigma_cross_track_km),
            )
            if math.isfinite(error_km) and abs(error_km) > spec_km
        )

    def to_dict(self) -> dict:
        """The record as JSON-ready values: ``scan_position`` (and ``for``, its earlier name), the measured
        fields, the derived % of FOV and ``flags``.

        Returns
        -------
        dict
            NaN where nothing was measured.
        """
        d = asdict(self)
        d["scan_position"] = d.pop("for_index")
        d["for"] = d["scan_position"]  # the earlier name, kept for scripts that read it
        d["flags"] = list(self.flags)
        d["d_alpha_pct_fov"] = self.d_alpha_pct_fov
        d["d_beta_pct_fov"] = self.d_beta_pct_fov
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in d.items()}

    @classmethod
    def from_dict(cls, d: dict) -> "ForOffset":
        """The record of :meth:`to_dict`, or of a stored row.

        Parameters
        ----------
        d : dict
            ``scan_position`` (or ``for``), ``flags`` and the measured fields; None is what was not measured
            (NaN, or 0 for a count).

        Returns
        -------
        ForOffset
            The record.
        """
        kw = {k: d[k] for k in MEASURED_FIELDS if k in d}
        kw = {k: (v if v is not None else 0 if k in COUNT_FIELDS else float("nan")) for k, v in kw.items()}
        position = d["scan_position"] if "scan_position" in d else d["for"]
        return cls(for_index=int(position), flags=tuple(d.get("flags", ())), **kw)


def measures(record: type = ForOffset) -> tuple[Measure, ...]:
    """The measured fields of a record in declaration order: what the outputs derive from.

    Parameters
    ----------
    record : type, optional
        :class:`ForOffset`, or a record extending it.

    Returns
    -------
    tuple of Measure
        The export, the tables, ``/metrics``, the time series and the store derive from these.
    """
    hints = typing.get_type_hints(record)
    return tuple(
        Measure(f.name, hints[f.name], **f.metadata["measure"])
        for f in fields(record)
        if "measure" in f.metadata
    )


# the measured fields of a FOR (all but its index and flags), in the order of the dataclass; those counted
MEASURED_FIELDS = tuple(m.name for m in measures())
COUNT_FIELDS = frozenset(m.name for m in measures() if m.kind is int)


@dataclass(frozen=True)
class DifferenceBin:
    """CrIS minus VIIRS BT (K) at the optimum of the samples whose CrIS BT lies in [low_k, low_k + width);
    the paper's Figure 15 (:func:`monitor.estimation.intercal.difference_bins`)."""

    low_k: float
    n: int
    mean_k: float
    std_k: float


@dataclass(frozen=True)
class GranuleInfo:
    """One assessed CrIS granule: its ID and times (ISO 8601), its files and the VIIRS files that covered it,
    the FOVs with geolocation and the FOVs used, and the processing metadata of its CrIS GEO and of the
    first VIIRS GEO (software and algorithm versions, auxiliary files: what change attribution compares)."""

    granule_id: str
    start: str
    end: str
    cris_geo: str
    cris_sdr: str
    viirs: list[str]
    n_fovs: int
    n_usable: int
    cris_meta: dict = field(default_factory=dict)
    viirs_meta: dict = field(default_factory=dict)

    @classmethod
    def from_dict(cls, d: dict) -> GranuleInfo:
        """A granule of a result file.

        Parameters
        ----------
        d : dict
            Its record in the result's JSON.

        Returns
        -------
        GranuleInfo
            The granule.
        """
        return cls(**{k: d[k] for k in cls.__dataclass_fields__ if k in d})


@dataclass(frozen=True)
class Skipped:
    """An input left out of an assessment: the *item* (a granule's key or a file) and why."""

    item: str
    reason: str


@dataclass
class AssessmentResult:
    """One assessment of one satellite over a set of granules; all 30 FORs, in FOR order."""

    satellite: str
    start: str
    end: str
    fors: list[ForOffset]
    granules: list[GranuleInfo] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    half_steps: int = DEFAULT_HALF_STEPS
    step_urad: float = DEFAULT_STEP_URAD
    cost_cube_k: np.ndarray | None = None  # (30, 2n+1, 2n+1), index i in-track, j cross-track
    difference_bins: list[DifferenceBin] = field(default_factory=list)  # the FORs refined, pooled
    notes: list[str] = field(default_factory=list)  # how the inputs were read, where that is not granules
    radiometry: list[RadiometryBin] = field(default_factory=list)  # CrIS minus VIIRS per band, binned
    difference_maps: list[DifferenceMap] = field(default_factory=list)  # one granule's FOVs per band
    # per FOR, the offsets' jackknife replicates (None where there are none): what pairs two bands' offsets;
    # the day's own, never written (to_dict) nor read back
    replicates: list[ForReplicates | None] = field(default_factory=list, repr=False, compare=False)

    def day_sigma_urad(self) -> float | None:
        """The day's precision, the one number a precision target is held to.

        The sigmas already count consecutive granules as fewer independent ones
        (:mod:`monitor.estimation.jackknife`).

        Returns
        -------
        float or None
            The median over FORs of the jackknife sigma in the worse direction, urad; None where no FOR has
            one.
        """
        medians = [
            float(np.median(v))
            for v in (
                [f.sigma_alpha_urad for f in self.fors if np.isfinite(f.sigma_alpha_urad)],
                [f.sigma_beta_urad for f in self.fors if np.isfinite(f.sigma_beta_urad)],
            )
            if v
        ]
        return max(medians) if medians else None

    def to_dict(self, with_cube: bool = False) -> dict:
        """The result as the JSON document ``crisgeo assess --out`` writes.

        Parameters
        ----------
        with_cube : bool, optional
            Include the 21 x 21 cost cube of every FOR (K).

        Returns
        -------
        dict
            The document.
        """
        d = {
            "satellite": self.satellite,
            "start": self.start,
            "end": self.end,
            "half_steps": self.half_steps,
            "step_urad": self.step_urad,
            "granules": [asdict(g) for g in self.granules],
            "skipped": [asdict(s) for s in self.skipped],
            "fors": [f.to_dict() for f in self.fors],
            "difference_bins": [asdict(b) for b in self.difference_bins],
            "notes": self.notes,
            "radiometry": [b.to_dict() for b in self.radiometry],
            "difference_maps": [m.to_dict() for m in self.difference_maps],
        }
        if with_cube and self.cost_cube_k is not None:
            d["cost_cube_k"] = np.round(self.cost_cube_k, 5).tolist()
        return d

    def to_json(self, with_cube: bool = True) -> str:
        """The result as JSON text (:meth:`to_dict`).

        Parameters
        ----------
        with_cube : bool, optional
            Include the cost cubes.

        Returns
        -------
        str
            The JSON.
        """
        return json.dumps(self.to_dict(with_cube), indent=1)

    @classmethod
    def from_dict(cls, d: dict) -> "AssessmentResult":
        """A result from its JSON document (:meth:`to_dict`).

        Parameters
        ----------
        d : dict
            The document.

        Returns
        -------
        AssessmentResult
            The result.
        """
        cube = d.get("cost_cube_k")
        return cls(
            satellite=d["satellite"],
            start=d["start"],
            end=d["end"],
            fors=[ForOffset.from_dict(f) for f in d["fors"]],
            granules=[GranuleInfo.from_dict(g) for g in d.get("granules", [])],
            skipped=[Skipped(**s) for s in d.get("skipped", [])],
            half_steps=int(d.get("half_steps", DEFAULT_HALF_STEPS)),
            step_urad=float(d.get("step_urad", DEFAULT_STEP_URAD)),
            cost_cube_k=None if cube is None else np.asarray(cube, float),
            difference_bins=[DifferenceBin(**b) for b in d.get("difference_bins", [])],
            notes=list(d.get("notes", [])),
            radiometry=[RadiometryBin.from_dict(b) for b in d.get("radiometry", [])],
            difference_maps=[DifferenceMap.from_dict(m) for m in d.get("difference_maps", [])],
        )

    @classmethod
    def from_json(cls, text: str) -> "AssessmentResult":
        """A result from its JSON text (:meth:`to_json`).

        Parameters
        ----------
        text : str
            The JSON.

        Returns
        -------
        AssessmentResult
            The result.
        """
        return cls.from_dict(json.loads(text))


@dataclass(frozen=True)
class SceneDecision:
    """What scene selection decided for one CrIS granule, why, and its inhomogeneity score (K) where it was
    scored."""

    granule: str
    decision: Decision
    reason: str
    score_k: float | None = None


@dataclass(frozen=True)
class DayPrecision:
    """How far a satellite-day went for its precision: the granules assessed in how many batches, the sigma
    they reached (urad, :meth:`monitor.core.result.AssessmentResult.day_sigma_urad`), the target (None:
    none set), why it stopped, and the bytes read per assessed granule (MB). Stored in the run's summary
    (``precision``), shown by ``status``, the report and ``/metrics``."""

    granules: int
    batches: int
    sigma_urad: float | None
    target_sigma_urad: float | None
    stop: DayStop
    mb_per_granule: float | None = None

    def text(self) -> str:
        """One line: ``24 granules in 2 batches, sigma 61 urad (target 60): target reached``.

        Returns
        -------
        str
            The line.
        """
        sigma = "no sigma" if self.sigma_urad is None else f"sigma {self.sigma_urad:.0f} urad"
        target = "" if self.target_sigma_urad is None else f" (target {self.target_sigma_urad:g})"
        per = "" if self.mb_per_granule is None else f", {self.mb_per_granule:.0f} MB per granule"
        return f"{self.granules} granules in {self.batches} batch(es), {sigma}{target}{per}: {self.stop}"

    def to_dict(self) -> dict:
        """The JSON of the run summary's ``precision``.

        Returns
        -------
        dict
            Its fields.
        """
        return {**asdict(self), "stop": str(self.stop)}

    @classmethod
    def from_summary(cls, summary: str | None) -> "DayPrecision | None":
        """The precision a run's stored summary records.

        Parameters
        ----------
        summary : str or None
            The run's summary, JSON.

        Returns
        -------
        DayPrecision or None
            None where it records none (days without results).
        """
        body = json.loads(summary).get("precision") if summary else None
        return None if body is None else cls(**{**body, "stop": DayStop(body["stop"])})


def worst_for(fors: Iterable[ForOffset]) -> ForOffset | None:
    """The reliable FOR with the largest :attr:`ForOffset.worst_km`.

    Parameters
    ----------
    fors : iterable of ForOffset
        A day's FORs.

    Returns
    -------
    ForOffset or None
        None when none was measured.
    """
    ok = [f for f in fors if f.reliable and math.isfinite(f.worst_km)]
    return max(ok, key=lambda f: f.worst_km) if ok else None
