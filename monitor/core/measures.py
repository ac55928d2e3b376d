"""How a measured per-FOR field is declared: its unit as CF writes it, its meaning, and its outputs.

:class:`monitor.core.result.ForOffset` declares every per-FOR field once with :func:`measured`; the export,
the tables' units, ``/metrics`` (its :class:`Family` and the SI factor of its unit), the time-series lines
and the store's columns derive from that declaration.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field
from typing import Any

from monitor.core.constants import URAD


@dataclass(frozen=True)
class Family:
    """A gauge family of ``/metrics`` that per-FOR fields are published in: its name (in base units, by
    Prometheus' conventions), its help, and the label that tells its fields apart (empty: one field)."""

    name: str
    help: str
    label: str = ""


# the /metrics families of the per-FOR fields (:mod:`monitor.service.outputs.metrics` adds the FOR's labels)
OFFSET_RADIANS = Family(
    "crisgeo_for_offset_radians",
    "Latest LOS offset per FOR (spacecraft frame; the turn to apply to the CrIS LOS)",
    "direction",
)
OFFSET_METERS = Family("crisgeo_for_offset_meters", "Latest offset per FOR on the ground", "direction")
CALIBRATION_BIAS = Family(
    "crisgeo_for_calibration_bias_kelvin",
    "Latest CrIS minus VIIRS I5 BT at the reference temperature (280 K) per FOR, at the optimum",
)
CALIBRATION_GAIN = Family(
    "crisgeo_for_calibration_gain_ratio",
    "Latest CrIS minus VIIRS I5 gain difference per FOR (fraction of the BT's departure from 280 K)",
)
RESPONSE_WIDTH = Family(
    "crisgeo_for_response_full_width_radians",
    "Latest full width of the CrIS FOV spatial response fitted per FOR, at a level of its peak",
    "level",
)
CRIS_MINUS_VIIRS = Family(
    "crisgeo_for_cris_minus_viirs_kelvin",
    "Latest CrIS minus VIIRS BT per FOR and VIIRS band, the mean over the FOVs uniform in VIIRS",
    "band",
)
FOV_ROWS = Family(
    "crisgeo_for_fov_rows_offset_radians",
    "Latest offset of the FOV rows ahead (FOVs 7-9) minus the rows behind (FOVs 1-3) per FOR",
    "direction",
)
# a field's unit (as CF writes it) -> the factor to the SI unit /metrics publishes it in
TO_BASE_UNIT = {"urad": URAD, "km": 1000.0, "K": 1.0, "percent": 0.01, "1": 1.0, "m K-1": 1.0}


@dataclass(frozen=True)
class Measure:
    """A measured per-FOR field, as :class:`ForOffset` declares it: its name (ending in its unit), its unit
    as CF writes it, its meaning; whether it tells the quality of a measurement (an uncertainty, a cost)
    rather than being one; whether the time series carries it; where ``/metrics`` publishes it (a family
    and the value of its label), if it does; the VIIRS band it belongs to, for a field measured per band
    (``cris_minus_viirs_k_M15``: its quantity ``cris_minus_viirs_k`` in band ``M15``). The export, the text
    tables' units, ``/metrics``, the time series and the store's columns all derive from these
    (:func:`measures`)."""

    name: str
    kind: type
    unit: str
    meaning: str
    quality: bool = False
    series: bool = True
    metric: tuple[Family, str] | None = None
    band: str | None = None

    @property
    def quantity(self) -> str:  # numpydoc ignore=RT01
        """The name without its band (``cris_minus_viirs_k`` of ``cris_minus_viirs_k_M15``)."""
        return self.name if self.band is None else self.name.removesuffix(f"_{self.band}")

    @property
    def to_base_unit(self) -> float:  # numpydoc ignore=RT01
        """The factor from the field's unit to the SI unit of ``/metrics``."""
        return TO_BASE_UNIT[self.unit]


def measured(
    unit: str,
    meaning: str,
    default: Any = MISSING,
    quality: bool = False,
    series: bool = True,
    metric: tuple[Family, str] | None = None,
    band: str | None = None,
) -> Any:
    """Declare a measured field of :class:`ForOffset` (or of a record extending it).

    Parameters
    ----------
    unit : str
        Its unit as CF writes it (``urad``, ``km``, ``K``, ``1`` for a count).
    meaning : str
        What it is, for the export's long name and the tables.
    default : object, optional
        Its default; MISSING: required.
    quality : bool, optional
        Whether it tells the quality of a measurement (an uncertainty, a cost) rather than being one.
    series : bool, optional
        Whether the time series carries it.
    metric : tuple of (Family, str), optional
        The ``/metrics`` family that publishes it, and its label value there.
    band : str, optional
        The VIIRS band of a field measured per band; its name ends in ``_<band>``.

    Returns
    -------
    dataclasses.Field
        The field, its :class:`Measure` in its metadata.
    """
    spec = {
        "unit": unit,
        "meaning": meaning,
        "quality": quality,
        "series": series,
        "metric": metric,
        "band": band,
    }
    return field(default=default, metadata={"measure": spec})


NAN = float("nan")
SIGMA = "uncertainty (1 sigma) of the"
UNIFORM = "mean over the day's FOVs uniform in VIIRS, on the assessed geolocation"


def difference_of(band: str) -> Any:
    """The declaration of a band's CrIS minus VIIRS difference (:mod:`monitor.matchup.radiometry`).

    Parameters
    ----------
    band : str
        The VIIRS band.

    Returns
    -------
    dataclasses.Field
        The field (:func:`measured`).
    """
    return measured(
        "K",
        f"CrIS minus VIIRS {band} brightness temperature, {UNIFORM}",
        NAN,
        metric=(CRIS_MINUS_VIIRS, band),
        band=band,
    )


def difference_sigma_of(band: str) -> Any:
    """The declaration of the sigma of a band's CrIS minus VIIRS difference.

    Parameters
    ----------
    band : str
        The VIIRS band.

    Returns
    -------
    dataclasses.Field
        The field (:func:`measured`).
    """
    return measured("K", f"{SIGMA} CrIS minus VIIRS {band} difference", NAN, quality=True, band=band)
