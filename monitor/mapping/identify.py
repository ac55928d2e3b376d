"""Which engineering packet a day's LOS fingerprint points to, and the fingerprint as the command prints it.

Each EP's model FOV-5 angles (Wang et al. 2017, equations 14-18, and the mounting) are compared with the
fingerprint's per-FOR medians (:mod:`monitor.mapping.fingerprint`); the EPs are ranked by how well they
explain the day.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from monitor.core.constants import URAD
from monitor.core.tables import Column, text_table
from monitor.geometry.ep_model import fov5_angles

if TYPE_CHECKING:
    from monitor.mapping.fingerprint import DayPrint


@dataclass(frozen=True)
class EpMatch:
    """How well one EP's model explains a fingerprint: per-FOR residual (fingerprint - model, urad)."""

    name: str
    satellite: str
    version: str
    d_alpha_urad: np.ndarray
    d_beta_urad: np.ndarray

    @property
    def rms_urad(self) -> float:  # numpydoc ignore=RT01
        """RMS over FORs of the residual in both directions."""
        return float(np.sqrt(np.nanmean(np.concatenate([self.d_alpha_urad, self.d_beta_urad]) ** 2)))

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "satellite": self.satellite,
            "version": self.version,
            "rms_urad": self.rms_urad,
            "d_alpha_urad": np.round(self.d_alpha_urad, 1).tolist(),
            "d_beta_urad": np.round(self.d_beta_urad, 1).tolist(),
        }


def identify_ep(day: DayPrint, library: dict, satellite: str | None = None) -> list[EpMatch]:
    """The EPs of *library* (name -> EngineeringPacket), best first, by how well they explain *day*.

    Each EP's model FOV-5 angles (equations 14-18 and the mounting) are compared with the fingerprint's
    per-FOR medians. With *satellite*, EPs of other satellites are left out. On real NOAA-20 data the
    right EP leaves ~30 urad (the servo and in-track residuals of docs/jpss-formats.md 2.3); a wrong one,
    hundreds.

    Parameters
    ----------
    day : DayPrint
        The day's print.
    library : dict of str to EngineeringPacket
        The EPs to identify from, by name.
    satellite : str, optional
        Leave out the EPs of other satellites.

    Returns
    -------
    list of EpMatch
        Best first.
    """
    matches = []
    for name, ep in library.items():
        if satellite is not None and ep.satellite != satellite:
            continue
        alpha, beta = fov5_angles(ep)
        matches.append(
            EpMatch(
                name, ep.satellite, ep.version, day.alpha_urad - alpha / URAD, day.beta_urad - beta / URAD
            )
        )
    return sorted(matches, key=lambda m: m.rms_urad)


MATCH_COLUMNS = (
    Column("EP", "name", "", 40, align="<"),
    Column("sat", "satellite", "", 4, align="<"),
    Column("version", "version", "", 20, align="<"),
    Column("rms", "rms_urad", ".1f", 9, "urad"),
)


@dataclass(frozen=True)
class _ForRow:
    """One FOR's pair of values, for the per-FOR tables below."""

    for_index: int
    alpha_urad: float
    beta_urad: float
    sd_alpha_urad: float = float("nan")
    sd_beta_urad: float = float("nan")


RESIDUAL_COLUMNS = (
    Column("FOR", "for_index", "d", 3),
    Column("in-track", "alpha_urad", ".1f", 9, "urad"),
    Column("x-track", "beta_urad", ".1f", 9, "urad"),
)
PRINT_COLUMNS = (
    Column("FOR", "for_index", "d", 3),
    Column("alpha5", "alpha_urad", ".1f", 10, "urad"),
    Column("sd", "sd_alpha_urad", ".1f", 5, "urad"),
    Column("beta5", "beta_urad", ".1f", 10, "urad"),
    Column("sd", "sd_beta_urad", ".1f", 5, "urad"),
)


def format_matches(matches: list[EpMatch]) -> str:
    """Ranked EP matches, with the best one's per-FOR residual.

    Parameters
    ----------
    matches : list of EpMatch
        Ranked matches.

    Returns
    -------
    str
        The text.
    """
    if not matches:
        return "no EP in the library to compare with"
    lines = ["EP identification (fingerprint - EP model, FOV 5):"]
    lines += text_table(matches, MATCH_COLUMNS, indent="  ")
    best = matches[0]
    lines.append(f"best: {best.name}; residual per FOR (fingerprint - EP model):")
    rows = [
        _ForRow(k + 1, a, b) for k, (a, b) in enumerate(zip(best.d_alpha_urad, best.d_beta_urad, strict=True))
    ]
    lines += text_table(rows, RESIDUAL_COLUMNS, indent="  ")
    return "\n".join(lines)


def format_print(day: DayPrint) -> str:
    """The per-FOR table printed by ``crisgeo fingerprint`` (SBF angles of FOV 5; sd: scan to scan).

    Parameters
    ----------
    day : DayPrint
        The day's print.

    Returns
    -------
    str
        The table.
    """
    rows = [
        _ForRow(k + 1, day.alpha_urad[k], day.beta_urad[k], day.sd_alpha_urad[k], day.sd_beta_urad[k])
        for k in range(len(day.alpha_urad))
    ]
    return "\n".join(
        [f"{len(day.granules)} granule(s); SBF angles of FOV 5, sd scan to scan"]
        + text_table(rows, PRINT_COLUMNS)
    )
