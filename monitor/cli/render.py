"""What ``crisgeo assess`` and ``crisgeo run`` print of an assessment: its span, the FOR table
(:mod:`monitor.core.tables`, as ``crisgeo status`` and the report show it) and what was skipped."""

from __future__ import annotations

from monitor.core.result import AssessmentResult
from monitor.core.tables import for_table


def result_text(result: AssessmentResult) -> str:
    """What ``crisgeo assess`` and ``crisgeo run`` print of an assessment."""
    lines = [f"{result.satellite} {result.start} .. {result.end}, {len(result.granules)} granules"]
    lines += for_table(result.fors)
    lines += [f"skipped {s.item}: {s.reason}" for s in result.skipped]
    return "\n".join(lines)
