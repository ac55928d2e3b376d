"""The day's CrIS minus VIIRS per band beyond its per-FOR fields: the bins (by FOV, scene temperature, node)
and one granule's difference map per band, as :mod:`monitor.matchup.radiometry` makes them and the result,
the store and the report carry them; and each FOR's jackknife replicates, which pair the offsets read in two
bands (:mod:`monitor.estimation.band_pair`)."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass

import numpy as np

from monitor.core.vocabulary import BinnedBy


@dataclass(frozen=True)
class RadiometryBin:
    """CrIS minus VIIRS BT in one VIIRS *band* over the day's FOVs uniform in VIIRS that fall in one bin
    (:mod:`monitor.matchup.radiometry`): *by* FOV (*key* ``1``..``9``), scene temperature (*key* the bin's
    lower edge, K, of the VIIRS BT) or node (*key* ``ascending`` or ``descending``); the FOVs it holds, their
    mean difference and its jackknife sigma (K)."""

    band: str
    by: BinnedBy
    key: str
    n: int
    mean_k: float
    sigma_k: float

    def to_dict(self) -> dict:
        """The bin as JSON-ready values (None where nothing was measured).

        Returns
        -------
        dict
            Its fields.
        """
        d = {**asdict(self), "by": str(self.by)}
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}

    @classmethod
    def from_dict(cls, d: dict) -> RadiometryBin:
        """A bin of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            Its fields.

        Returns
        -------
        RadiometryBin
            The bin.
        """
        nan = float("nan")
        return cls(
            d["band"], BinnedBy(d["by"]), str(d["key"]), int(d["n"]),
            nan if d["mean_k"] is None else float(d["mean_k"]),
            nan if d["sigma_k"] is None else float(d["sigma_k"]),
        )  # fmt: skip


@dataclass(frozen=True)
class DifferenceMap:
    """CrIS minus VIIRS BT (K) at every FOV of one CrIS *granule* in one VIIRS *band*, where the day's
    assessed geolocation puts the FOVs: arrays (scans, 30, 9), NaN where a FOV was not mapped; *uniform*
    marks the FOVs the day's difference counts (:mod:`monitor.matchup.radiometry`)."""

    band: str
    granule: str
    latitude_deg: np.ndarray
    longitude_deg: np.ndarray
    difference_k: np.ndarray
    uniform: np.ndarray

    def to_dict(self) -> dict:
        """The map as JSON-ready values: degrees to 4 decimals, K to 3, None where not mapped.

        Returns
        -------
        dict
            Its fields, the arrays as nested lists.
        """

        def listed(a: np.ndarray, digits: int) -> list:
            return np.where(np.isfinite(a), np.round(a, digits), np.nan).astype(object).tolist()

        out = {
            "band": self.band,
            "granule": self.granule,
            "latitude_deg": listed(self.latitude_deg, 4),
            "longitude_deg": listed(self.longitude_deg, 4),
            "difference_k": listed(self.difference_k, 3),
            "uniform": self.uniform.astype(bool).tolist(),
        }
        return json.loads(json.dumps(out).replace("NaN", "null"))

    @classmethod
    def from_dict(cls, d: dict) -> DifferenceMap:
        """A map of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            Its fields.

        Returns
        -------
        DifferenceMap
            The map.
        """

        def array(v: list) -> np.ndarray:
            return np.array(v, dtype=float)  # None is NaN

        return cls(
            d["band"],
            d["granule"],
            array(d["latitude_deg"]),
            array(d["longitude_deg"]),
            array(d["difference_k"]),
            np.array(d["uniform"], bool),
        )


@dataclass(frozen=True)
class ForReplicates:
    """One FOR's delete-a-group jackknife replicates of its offsets (:mod:`monitor.estimation.jackknife`).

    Attributes
    ----------
    groups : tuple of (str, str)
        The first and last granule (granule ids) each replicate leaves out.
    alpha_urad, beta_urad : numpy.ndarray
        Each replicate's in-track and cross-track offset, urad, shape (G,).
    factor : float
        What the day's correlation of consecutive granules makes of the FOR's sigmas
        (:func:`~monitor.estimation.jackknife.correlation_factor`).
    """

    groups: tuple[tuple[str, str], ...]
    alpha_urad: np.ndarray
    beta_urad: np.ndarray
    factor: float = 1.0
