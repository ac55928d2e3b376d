"""What the commands print: the per-FOR offset table, the status summary, the geolocation comparison.

The command line parses its arguments and calls the service or the science; the text a person reads is
made here, from the typed results, so that ``crisgeo assess``, ``crisgeo run`` and ``crisgeo status``
(:meth:`monitor.status.Status.text`) show FORs the same way.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from monitor.result import AssessmentResult, ForOffset


@dataclass(frozen=True)
class Column:
    """One column of the FOR table: header, unit, width and how a FOR's value is written."""

    header: str
    unit: str
    width: int
    cell: Callable[[ForOffset], str]


def _num(attr: str, width: int, decimals: int) -> Callable[[ForOffset], str]:
    return lambda f: f"{getattr(f, attr):{width}.{decimals}f}"


FOR_COLUMNS = {
    "for": Column("FOR", "", 3, lambda f: f"{f.for_index:>3}"),
    "d_alpha": Column("d_alpha", "urad", 8, _num("d_alpha_urad", 8, 0)),
    "sigma_alpha": Column("+-", "", 5, _num("sigma_alpha_urad", 5, 0)),
    "d_beta": Column("d_beta", "urad", 8, _num("d_beta_urad", 8, 0)),
    "sigma_beta": Column("+-", "", 5, _num("sigma_beta_urad", 5, 0)),
    "in_track": Column("in-trk", "km", 7, _num("in_track_km", 7, 3)),
    "cross_track": Column("x-trk", "km", 7, _num("cross_track_km", 7, 3)),
    "total": Column("total", "km", 6, _num("total_km", 6, 3)),
    "n": Column("N", "", 5, lambda f: f"{f.n_samples:5d}"),
    "cost_min": Column("G_min", "K", 6, _num("cost_min_k", 6, 3)),
    "cost_zero": Column("G_0", "K", 6, _num("cost_zero_k", 6, 3)),
    "width_50": Column("FWHM", "urad", 6, _num("response_width_50_urad", 6, 0)),
}
FULL = tuple(FOR_COLUMNS)
BRIEF = ("for", "d_alpha", "d_beta", "in_track", "cross_track", "total")


def for_table(fors: list[ForOffset], columns: tuple[str, ...] = FULL, indent: str = "") -> list[str]:
    """The per-FOR table: a header line, a unit line (for the full table) and a line per FOR, flags last."""
    cols = [FOR_COLUMNS[c] for c in columns]
    lines = [indent + " ".join(f"{c.header:>{c.width}}" for c in cols) + "  flags"]
    if any(c.unit for c in cols):
        lines.append(indent + " ".join(f"{c.unit:>{c.width}}" for c in cols).rstrip())
    lines += [indent + " ".join(c.cell(f) for c in cols) + "  " + ",".join(f.flags) for f in fors]
    return lines


def result_text(result: AssessmentResult) -> str:
    """What ``crisgeo assess`` and ``crisgeo run`` print of an assessment."""
    lines = [f"{result.satellite} {result.start} .. {result.end}, {len(result.granules)} granules"]
    lines += for_table(result.fors)
    lines += [f"skipped {s.item}: {s.reason}" for s in result.skipped]
    return "\n".join(lines)
