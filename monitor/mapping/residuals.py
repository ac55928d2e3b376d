"""Geolocation beyond the engineering packet: a per-FOR residual table of the FOV-5 line of sight.

The EP model (:mod:`monitor.geometry.instrument`) reproduces the operational CrIS geolocation to tens of
metres, but not the scene-mirror servo corrections IDPS computes from telemetry carried only in the raw
data records (docs/jpss-formats.md 2.3: per-FOR cross-track residuals of -30..+64 urad, a constant ~+28 urad
in-track on NOAA-20). Those show in the GEO files themselves: the fingerprint (:mod:`monitor.fingerprint`)
measures each FOR's FOV-5 angles (alpha in-track, beta cross-track, spacecraft frame), and their difference
from the EP model's is the residual of that FOR.

Learned from a set of GEO granules, the table turns every FOV of FOR k by (d_alpha_k, d_beta_k) on top of
an EP's LOS; geolocating with a proposed EP plus the table then reproduces the operational geolocation
except for the EP change itself.

File (JSON): ``{"satellite", "ep_version", "granules": [...], "created", "fors": [{"for", "d_alpha_urad",
"d_beta_urad"}, ...]}``, 30 rows.
"""

from __future__ import annotations

import datetime as dt
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from monitor.constants import N_FOR, URAD
from monitor.errors import DataError
from monitor.geometry.frames import los_angles, los_from_angles
from monitor.geometry.instrument import EngineeringPacket, fov5_angles


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

    def apply(self, los_spacecraft) -> np.ndarray:
        """The LOS (30, 9, 3) (spacecraft frame) with every FOV of FOR k turned by the FOR's residual."""
        alpha, beta = los_angles(los_spacecraft)
        return los_from_angles(
            alpha + self.d_alpha_urad[:, None] * URAD, beta + self.d_beta_urad[:, None] * URAD
        )

    def table_for(self, granule) -> "ResidualTable":
        """The table to apply to *granule*: this one, whatever the granule."""
        return self

    def to_dict(self) -> dict:
        return {
            "satellite": self.satellite,
            "ep_version": self.ep_version,
            "granules": list(self.granules),
            "created": self.created,
            "fors": [
                {"for": k + 1, "d_alpha_urad": round(float(a), 3), "d_beta_urad": round(float(b), 3)}
                for k, (a, b) in enumerate(zip(self.d_alpha_urad, self.d_beta_urad, strict=True))
            ],
        }

    def write(self, path) -> Path:
        """Write the table as JSON to *path* (through a temporary name)."""
        path = Path(path)
        tmp = path.with_name(path.name + ".part")
        tmp.write_text(json.dumps(self.to_dict(), indent=1) + "\n")
        tmp.replace(path)
        return path


def learn(day, ep: EngineeringPacket) -> ResidualTable:
    """The residual table of a fingerprint *day* (:class:`monitor.fingerprint.DayPrint`) against *ep*:
    measured minus modelled FOV-5 angles per FOR. FORs the fingerprint could not measure get 0."""
    alpha, beta = fov5_angles(ep)
    return ResidualTable(
        ep.satellite,
        ep.version,
        np.nan_to_num(day.alpha_urad - alpha / URAD),
        np.nan_to_num(day.beta_urad - beta / URAD),
        tuple(day.granules),
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

    def __post_init__(self):
        object.__setattr__(self, "satellite", self.ep_in_force.satellite)

    def table_for(self, granule) -> ResidualTable:
        from monitor.fingerprint import day_print, granule_print

        return learn(day_print([granule_print(granule)]), self.ep_in_force)


def load(path) -> ResidualTable:
    """Read a residual table; :class:`ResidualError` naming file, field and value when it is unusable."""
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
    for i, row in enumerate(rows):
        if not isinstance(row, dict) or row.get("for") != i + 1:
            raise ResidualError(
                f"{path}: fors[{i}].for: expected {i + 1}, found "
                f"{row.get('for') if isinstance(row, dict) else row!r}"
            )
        for key, out in values.items():
            v = row.get(key)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or abs(v) > 5000:
                raise ResidualError(f"{path}: fors[{i}].{key}: {v!r} is not a number within +-5000 urad")
            out[i] = v
    return ResidualTable(
        str(doc["satellite"]),
        str(doc["ep_version"]),
        values["d_alpha_urad"],
        values["d_beta_urad"],
        tuple(doc.get("granules", ())),
        str(doc.get("created", "")),
    )
