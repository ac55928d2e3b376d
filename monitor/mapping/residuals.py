"""Geolocation beyond the engineering packet: a per-FOR residual table of the FOV-5 line of sight.

The EP model (:mod:`monitor.geometry.ep_model`) reproduces the operational CrIS geolocation to tens of
metres, but not the scene-mirror servo corrections IDPS computes from telemetry carried only in the raw
data records (docs/jpss-formats.md 2.3: per-FOR cross-track residuals of -30..+64 urad, a constant ~+28 urad
in-track on NOAA-20). Those show in the GEO files themselves: the fingerprint
(:mod:`monitor.mapping.fingerprint`) measures each FOR's FOV-5 angles (alpha in-track, beta cross-track,
spacecraft frame), and their difference
from the EP model's is the residual of that FOR.

Learned from a set of GEO granules, the table turns every FOV of FOR k by (d_alpha_k, d_beta_k) on top of
an EP's LOS; geolocating with a proposed EP plus the table then reproduces the operational geolocation
except for the EP change itself.

The servo corrections also move with time (on the real NOAA-20 granules by 10-25 urad within a minute,
README). A table cannot know a move after it was learned, but each granule it is applied to shows its own
FOV-5 angles: where they depart from the learning granules' by more than :data:`STALE_URAD` at some FOR,
the table is stale for that granule and a warning says so (the FORs, the departures, and the remedy,
:class:`OwnResiduals`).

File (JSON): ``{"satellite", "ep_version", "granules": [...], "created", "fors": [{"for", "d_alpha_urad",
"d_beta_urad", "fov5_alpha_urad", "fov5_beta_urad"}, ...]}``, 30 rows; the measured FOV-5 angles (null
where a FOR was not measured) may be absent in tables written before they were recorded.
"""

from __future__ import annotations

import datetime as dt
import json
import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from monitor.core.constants import N_FOR, PROCESSING_CHANGE_URAD, URAD
from monitor.core.errors import DataError
from monitor.geometry.ep_model import EngineeringPacket, fov5_angles
from monitor.geometry.frames import los_angles, los_from_angles
from monitor.mapping.fingerprint import DayPrint, day_print, granule_print
from monitor.sdr import CrisGeoGranule

log = logging.getLogger(__name__)

# Departure (urad) of a granule's own FOV-5 angles from the learning granules' beyond which the table no
# longer describes it: a processing change, as the fingerprint counts one.
STALE_URAD = PROCESSING_CHANGE_URAD
_FOV5_LIMIT_URAD = 1.0e6  # |a FOV-5 angle| in the spacecraft frame stays below ~0.9 rad


class ResidualError(DataError):
    """A residual table that cannot be used; the message names the file and the field."""


@dataclass(frozen=True)
class ResidualTable:
    """Per-FOR turn (urad) of the LOS, in-track alpha and cross-track beta, learned against one EP."""

    satellite: str
    ep_version: str
    d_alpha_urad: np.ndarray
    d_beta_urad: np.ndarray
    granules: tuple = ()
    created: str = field(
        default_factory=lambda: dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")
    )
    fov5_alpha_urad: np.ndarray | None = None  # FOV-5 angles the learning granules showed (spacecraft frame)
    fov5_beta_urad: np.ndarray | None = None

    def apply(self, los_spacecraft: np.ndarray) -> np.ndarray:
        """The LOS (30, 9, 3) (spacecraft frame) with every FOV of FOR k turned by the FOR's residual.

        Parameters
        ----------
        los_spacecraft : numpy.ndarray
            The EP model's LOS, spacecraft body frame, shape (30, 9, 3).

        Returns
        -------
        numpy.ndarray
            The LOS turned by the table's residuals, the same shape.
        """
        alpha, beta = los_angles(los_spacecraft)
        return los_from_angles(
            alpha + self.d_alpha_urad[:, None] * URAD, beta + self.d_beta_urad[:, None] * URAD
        )

    def departure_urad(self, granule: CrisGeoGranule) -> tuple[np.ndarray, np.ndarray] | None:
        """Per FOR, the FOV-5 angles (in-track, cross-track; urad) *granule* shows minus those of the learning
        granules (NaN where either was not measured); None for a table written without them.

        Parameters
        ----------
        granule : CrisGeoGranule
            A granule the table is applied to.

        Returns
        -------
        numpy.ndarray
            Per FOR the departure of its FOV-5 angles from those the table was learned from, urad.
        """
        if self.fov5_alpha_urad is None:
            return None

        p = granule_print(granule)
        return p.alpha_urad - self.fov5_alpha_urad, p.beta_urad - self.fov5_beta_urad

    def table_for(self, granule: CrisGeoGranule) -> "ResidualTable":
        """The table to apply to *granule*: this one. Warns when the granule departs from the learning
        granules by more than :data:`STALE_URAD` at some FOR, naming the FORs and the departures.

        Parameters
        ----------
        granule : CrisGeoGranule
            A granule.

        Returns
        -------
        ResidualTable
            The table to apply to it.
        """
        departure = self.departure_urad(granule)
        if departure is not None:
            da, db = departure
            with np.errstate(invalid="ignore"):
                stale = np.nonzero((np.abs(da) > STALE_URAD) | (np.abs(db) > STALE_URAD))[0]
            if stale.size:
                fors = ", ".join(f"{k + 1} ({da[k]:+.1f}/{db[k]:+.1f})" for k in stale)
                log.warning(
                    "%s: the residual table (learned from %d granule(s)) no longer describes this granule: "
                    "its FOV-5 angles depart by more than %g urad (in-track/cross-track) at FOR %s; the "
                    "scene-mirror servo has moved since, and the residual learned from the granule itself "
                    "(--own-residuals) follows such moves",
                    granule.meta.path,
                    len(self.granules),
                    STALE_URAD,
                    fors,
                )
        return self

    def to_dict(self) -> dict:
        """The table as the JSON document of the module docstring.

        Returns
        -------
        dict
            Its JSON.
        """
        rows: list[dict[str, float | None]] = [
            {"for": k + 1, "d_alpha_urad": round(float(a), 3), "d_beta_urad": round(float(b), 3)}
            for k, (a, b) in enumerate(zip(self.d_alpha_urad, self.d_beta_urad, strict=True))
        ]
        if self.fov5_alpha_urad is not None and self.fov5_beta_urad is not None:
            for row, a, b in zip(rows, self.fov5_alpha_urad, self.fov5_beta_urad, strict=True):
                row["fov5_alpha_urad"] = round(float(a), 3) if np.isfinite(a) else None
                row["fov5_beta_urad"] = round(float(b), 3) if np.isfinite(b) else None
        return {
            "satellite": self.satellite,
            "ep_version": self.ep_version,
            "granules": list(self.granules),
            "created": self.created,
            "fors": rows,
        }

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the table as JSON to *path* (through a temporary name).

        Parameters
        ----------
        path : str or os.PathLike
            The file.

        Returns
        -------
        Path
            The file written.
        """
        path = Path(path)
        tmp = path.with_name(path.name + ".part")
        tmp.write_text(json.dumps(self.to_dict(), indent=1) + "\n")
        tmp.replace(path)
        return path


def learn(day: DayPrint, ep: EngineeringPacket) -> ResidualTable:
    """The residual table of a fingerprint *day* (:class:`monitor.mapping.fingerprint.DayPrint`) against *ep*:
    measured minus modelled FOV-5 angles per FOR. FORs the fingerprint could not measure get 0.

    Parameters
    ----------
    day : DayPrint
        The day's fingerprint.
    ep : EngineeringPacket
        The EP the residuals are learned against.

    Returns
    -------
    ResidualTable
        The per-FOR FOV-5 residual.
    """
    alpha, beta = fov5_angles(ep)
    return ResidualTable(
        ep.satellite,
        ep.version,
        np.nan_to_num(day.alpha_urad - alpha / URAD),
        np.nan_to_num(day.beta_urad - beta / URAD),
        tuple(day.granules),
        fov5_alpha_urad=np.asarray(day.alpha_urad, float),
        fov5_beta_urad=np.asarray(day.beta_urad, float),
    )


@dataclass(frozen=True)
class OwnResiduals:
    """Each granule's own residual against the EP it was made with (*ep_in_force*): learned from the
    granule being regeolocated, so that the servo corrections of that very minute carry over.

    On the real NOAA-20 granules 6-10 this leaves a median of 2 m and p99 <= 16 m at every FOR, where a
    table learned from granules 1-5 leaves 52-74 m at FOR 1, 2 and 30 (the servo drifts in between).
    """

    ep_in_force: EngineeringPacket
    satellite: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "satellite", self.ep_in_force.satellite)

    def table_for(self, granule: CrisGeoGranule) -> ResidualTable:
        return learn(day_print([granule_print(granule)]), self.ep_in_force)


def load(path: str | os.PathLike[str]) -> ResidualTable:
    """Read a residual table; :class:`ResidualError` naming file, field and value when it is unusable.

    Parameters
    ----------
    path : str or os.PathLike
        A residual table's JSON.

    Returns
    -------
    ResidualTable
        The table.
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError) as exc:
        raise ResidualError(f"{path}: (file): unreadable ({exc})") from None
    except json.JSONDecodeError as exc:
        raise ResidualError(f"{path}: (file): not JSON ({exc.msg} at line {exc.lineno})") from None
    if not isinstance(doc, dict):
        raise ResidualError(f"{path}: (file): expected an object, found {type(doc).__name__}")
    for key in ("satellite", "ep_version", "fors"):
        if key not in doc:
            raise ResidualError(f"{path}: {key}: missing")
    rows = doc["fors"]
    if not isinstance(rows, list) or len(rows) != N_FOR:
        raise ResidualError(
            f"{path}: fors: expected {N_FOR} rows, found "
            f"{len(rows) if isinstance(rows, list) else type(rows).__name__}"
        )
    values = {"d_alpha_urad": np.empty(N_FOR), "d_beta_urad": np.empty(N_FOR)}
    measured = {"fov5_alpha_urad": np.empty(N_FOR), "fov5_beta_urad": np.empty(N_FOR)}
    has_measured = isinstance(rows[0], dict) and "fov5_alpha_urad" in rows[0]
    for i, row in enumerate(rows):
        if not isinstance(row, dict) or row.get("for") != i + 1:
            raise ResidualError(
                f"{path}: fors[{i}].for: expected {i + 1}, found "
                f"{row.get('for') if isinstance(row, dict) else row!r}"
            )
        for key, out in values.items():
            out[i] = _number(path, i, key, row.get(key), 5000.0)
        for key, out in measured.items() if has_measured else ():
            if key not in row:
                raise ResidualError(f"{path}: fors[{i}].{key}: missing (FOR 1 has it)")
            v = row[key]
            out[i] = np.nan if v is None else _number(path, i, key, v, _FOV5_LIMIT_URAD)
    return ResidualTable(
        str(doc["satellite"]),
        str(doc["ep_version"]),
        values["d_alpha_urad"],
        values["d_beta_urad"],
        tuple(doc.get("granules", ())),
        str(doc.get("created", "")),
        measured["fov5_alpha_urad"] if has_measured else None,
        measured["fov5_beta_urad"] if has_measured else None,
    )


def _number(path: object, i: int, key: str, v: object, limit_urad: float) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or abs(v) > limit_urad:
        raise ResidualError(f"{path}: fors[{i}].{key}: {v!r} is not a number within +-{limit_urad:g} urad")
    return float(v)
