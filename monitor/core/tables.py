"""Tables as data: every table the command line, the report and the messages show declares its columns
once here or beside its rows, and :func:`text_table` (text) or :meth:`Column.text` (a cell, for HTML) writes
them. The FOR table (:data:`FOR_COLUMNS`) is the one ``crisgeo assess``, ``run`` and ``status`` print and
the report shows.

On the ground floor, so that the science (the fingerprint, the mapping angles), the alerts and the service
all reach it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from operator import attrgetter
from typing import Any

from monitor.core.result import ForOffset, measures


@dataclass(frozen=True)
class Column:
    """One column: its header and unit, how a row's value is read (*value*: an attribute name or a
    function of the row) and written (*fmt*, a format spec), its width and alignment (``>`` or ``<``)."""

    header: str
    value: str | Callable[[Any], Any]
    fmt: str = ""
    width: int = 0
    unit: str = ""
    align: str = ">"

    def text(self, row: Any) -> str:
        """A row's value as text, unpadded.

        Parameters
        ----------
        row : object
            The row (a record whose attribute, or function, gives the value).

        Returns
        -------
        str
            The value written with the column's format.
        """
        get = attrgetter(self.value) if isinstance(self.value, str) else self.value
        return format(get(row), self.fmt)

    def pad(self, text: str) -> str:
        """Text aligned to the column's width.

        Parameters
        ----------
        text : str
            The text.

        Returns
        -------
        str
            Padded to the width, left or right as the column aligns.
        """
        return f"{text:{self.align}{self.width}}"


def text_table(rows: Iterable[Any], columns: Sequence[Column], indent: str = "") -> list[str]:
    """A table as text lines: a header, a unit line when any column has a unit, and a line per row.

    Parameters
    ----------
    rows : iterable
        The rows.
    columns : sequence of Column
        The columns.
    indent : str, optional
        Put before every line.

    Returns
    -------
    list of str
        The lines, trailing blanks cut.
    """
    lines = [indent + " ".join(c.pad(c.header) for c in columns)]
    if any(c.unit for c in columns):
        lines.append(indent + " ".join(c.pad(c.unit) for c in columns))
    lines += [indent + " ".join(c.pad(c.text(r)) for c in columns) for r in rows]
    return [line.rstrip() for line in lines]


def _flags(f: ForOffset) -> str:
    return ",".join(f.flags)


def field_column(header: str, name: str, fmt: str, width: int, record: type = ForOffset) -> Column:
    """The column of a measured field, its unit the declaration's (a count has none).

    Parameters
    ----------
    header : str
        The column's header.
    name : str
        The field.
    fmt : str
        Its format spec.
    width : int
        The column's width.
    record : type, optional
        The record declaring the field.

    Returns
    -------
    Column
        The column.
    """
    unit = next(m.unit for m in measures(record) if m.name == name)
    return Column(header, name, fmt, width, "" if unit == "1" else unit)


FOR_COLUMNS = {
    "for": Column("FOR", "for_index", "d", 3),
    "d_alpha": field_column("d_alpha", "d_alpha_urad", ".0f", 8),
    "sigma_alpha": Column("+-", "sigma_alpha_urad", ".0f", 5),  # the unit is the offset's, left of it
    "d_beta": field_column("d_beta", "d_beta_urad", ".0f", 8),
    "sigma_beta": Column("+-", "sigma_beta_urad", ".0f", 5),
    "alpha_pct_fov": Column("d_alpha", "d_alpha_pct_fov", ".1f", 7, "% FOV"),
    "beta_pct_fov": Column("d_beta", "d_beta_pct_fov", ".1f", 7, "% FOV"),
    "in_track": field_column("in-trk", "in_track_km", ".3f", 7),
    "cross_track": field_column("x-trk", "cross_track_km", ".3f", 7),
    "total": field_column("total", "total_km", ".3f", 6),
    "n": field_column("N", "n_samples", "d", 5),
    "cost_min": field_column("G_min", "cost_min_k", ".3f", 6),
    "cost_zero": field_column("G_0", "cost_zero_k", ".3f", 6),
    "width_50": field_column("FWHM", "response_width_50_urad", ".0f", 6),
    "rows_alpha": field_column("rows_a", "fov_rows_alpha_urad", ".0f", 7),
    "rows_beta": field_column("rows_b", "fov_rows_beta_urad", ".0f", 7),
    "flags": Column("flags", _flags, "", 0, "", "<"),
}
# the column sets: what assess and run print, what status prints, what the report shows
FULL = (
    "for", "d_alpha", "sigma_alpha", "d_beta", "sigma_beta", "in_track", "cross_track", "total", "n",
    "cost_min", "cost_zero", "width_50", "flags",
)  # fmt: skip
BRIEF = ("for", "d_alpha", "d_beta", "in_track", "cross_track", "total", "flags")
REPORT = FULL[:5] + ("alpha_pct_fov", "beta_pct_fov") + FULL[5:-1] + ("rows_alpha", "rows_beta", "flags")


def for_table(fors: Iterable[ForOffset], columns: tuple[str, ...] = FULL, indent: str = "") -> list[str]:
    """The per-FOR table: header, units, a line per FOR.

    Parameters
    ----------
    fors : iterable of ForOffset
        The FORs.
    columns : tuple of str, optional
        Keys of :data:`FOR_COLUMNS`.
    indent : str, optional
        Put before every line.

    Returns
    -------
    list of str
        The lines.
    """
    return text_table(fors, [FOR_COLUMNS[c] for c in columns], indent)
