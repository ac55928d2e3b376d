"""New scene-mirror angles from an assessment (Wang et al. 2017, section 4.1).

The assessment gives, per FOR, the turn (d_alpha, d_beta) that puts the CrIS LOS on VIIRS. Which of
the table-2 angles is wrong cannot be told from 2 x 30 numbers, so, as in the paper, the 2 x 30
scene-selection-mirror angles absorb the whole correction (equations 19-23). FORs whose offsets are
not trustworthy (flagged or missing) keep their angles, and the table says why.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

import numpy as np

from monitor.core.constants import N_FOR, URAD
from monitor.core.errors import DataError
from monitor.core.result import AssessmentResult, ForOffset
from monitor.core.tables import Column, text_table
from monitor.geometry.ep_model import EngineeringPacket, corrected_ssm_angles


@dataclass(frozen=True)
class AngleRow:
    """Old and new scene-mirror angles of one FOR (urad); *kept* names why a FOR was left unchanged."""

    for_index: int
    old_roll_urad: float
    new_roll_urad: float
    old_pitch_urad: float
    new_pitch_urad: float
    d_alpha_urad: float
    d_beta_urad: float
    kept: str = ""

    @property
    def d_roll_urad(self) -> float:  # numpydoc ignore=RT01
        """Change of the cross-track (roll) mirror angle, new minus old (urad)."""
        return self.new_roll_urad - self.old_roll_urad

    @property
    def d_pitch_urad(self) -> float:  # numpydoc ignore=RT01
        """Change of the in-track (pitch) mirror angle, new minus old (urad)."""
        return self.new_pitch_urad - self.old_pitch_urad

    def to_dict(self) -> dict:
        return {
            "for": self.for_index,
            "old_roll_urad": self.old_roll_urad,
            "new_roll_urad": self.new_roll_urad,
            "d_roll_urad": self.d_roll_urad,
            "old_pitch_urad": self.old_pitch_urad,
            "new_pitch_urad": self.new_pitch_urad,
            "d_pitch_urad": self.d_pitch_urad,
            "d_alpha_urad": self.d_alpha_urad,
            "d_beta_urad": self.d_beta_urad,
            "kept": self.kept,
        }


ANGLE_COLUMNS = (
    Column("FOR", "for_index", "d", 3),
    Column("roll_old", "old_roll_urad", ".1f", 10, "urad"),
    Column("roll_new", "new_roll_urad", ".1f", 10, "urad"),
    Column("d_roll", "d_roll_urad", ".1f", 8, "urad"),
    Column("pitch_old", "old_pitch_urad", ".1f", 10, "urad"),
    Column("pitch_new", "new_pitch_urad", ".1f", 10, "urad"),
    Column("d_pitch", "d_pitch_urad", ".1f", 8, "urad"),
    Column("d_alpha", "d_alpha_urad", ".1f", 8, "urad"),
    Column("d_beta", "d_beta_urad", ".1f", 8, "urad"),
    Column("note", "kept", "", 0, align="<"),
)


@dataclass(frozen=True)
class Optimization:
    """The proposed EP and the per-FOR table behind it."""

    ep: EngineeringPacket
    rows: list

    @property
    def kept(self) -> list:  # numpydoc ignore=RT01
        """The rows whose old angles were kept, with why (``kept`` names the reason)."""
        return [r for r in self.rows if r.kept]

    def table(self) -> str:
        """The old/new angle table as fixed-width text (urad; :data:`ANGLE_COLUMNS`).

        Returns
        -------
        list of dict
            Per FOR the old and new scene-mirror angles, urad.
        """
        lines = ["roll: ActualCrosstrackAngleRoll, pitch: ActualIntrackAnglePitch; d_alpha, d_beta: assessed"]
        lines += text_table(self.rows, ANGLE_COLUMNS)
        if self.kept:
            lines.append(
                f"{len(self.kept)} FOR(s) kept their angles: "
                + ", ".join(f"FOR {r.for_index} ({r.kept})" for r in self.kept)
            )
        return "\n".join(lines)


def _why_kept(f: ForOffset) -> str:
    if not (np.isfinite(f.d_alpha_urad) and np.isfinite(f.d_beta_urad)):
        return "no offset (NaN)"
    if not f.reliable:
        return "flagged " + "+".join(f.flags)
    return ""


def optimize(result: AssessmentResult, ep: EngineeringPacket, source: str = "") -> Optimization:
    """The EP with scene-mirror angles that cancel the offsets of *result*, assessed on data made with *ep*.

    Raises ValueError when the result is for another satellite than the EP or does not have 30 FORs.

    Parameters
    ----------
    result : AssessmentResult
        The assessment whose offsets are corrected.
    ep : EngineeringPacket
        The EP in force when the assessed data were made.
    source : str, optional
        What the result came from, recorded in the new EP's provenance.

    Returns
    -------
    Optimization
        The new EP and the angles' table.
    """
    if result.satellite != ep.satellite:
        raise DataError(
            f"assessment {source or ''} is for {result.satellite}, the EP {ep.version} for "
            f"{ep.satellite}: an EP is only corrected by its own satellite's assessment"
        )
    if len(result.fors) != N_FOR or [f.for_index for f in result.fors] != list(range(1, N_FOR + 1)):
        raise DataError(f"assessment {source}: needs FORs 1..30 in order, got {len(result.fors)} entries")
    reasons = [_why_kept(f) for f in result.fors]
    use = np.array([not r for r in reasons])
    d_alpha = np.array([f.d_alpha_urad for f in result.fors], float)
    d_beta = np.array([f.d_beta_urad for f in result.fors], float)
    roll, pitch = corrected_ssm_angles(
        ep, np.where(use, d_alpha, 0.0) * URAD, np.where(use, d_beta, 0.0) * URAD
    )
    roll = np.where(use, roll, ep.ssm_crosstrack_roll_rad)
    pitch = np.where(use, pitch, ep.ssm_intrack_pitch_rad)
    granules = list(result.granules)
    provenance = {
        "derived_from": ep.version,
        "derived_by": "crisgeo optimize (Wang et al. 2017 section 4.1, equations 19-23)",
        "created": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
        "assessment": {
            "file": source,
            "satellite": result.satellite,
            "start": result.start,
            "end": result.end,
            "n_granules": len(granules),
            "first_granule": granules[0].granule_id if granules else None,
            "last_granule": granules[-1].granule_id if granules else None,
        },
        "fors_kept": {str(f.for_index): r for f, r in zip(result.fors, reasons, strict=True) if r},
    }
    new_ep = ep.with_ssm_angles(roll, pitch, version=f"{ep.version}+crisgeo", provenance=provenance)
    rows = [
        AngleRow(
            k + 1,
            ep.ssm_crosstrack_roll_rad[k] / URAD,
            roll[k] / URAD,
            ep.ssm_intrack_pitch_rad[k] / URAD,
            pitch[k] / URAD,
            d_alpha[k],
            d_beta[k],
            reasons[k],
        )
        for k in range(N_FOR)
    ]
    return Optimization(new_ep, rows)
