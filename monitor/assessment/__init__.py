"""The assessment of a day: granules or reference collocations in, the typed result out.

This is the service's one door into the science (an import contract, ``pyproject.toml``, says so): a
satellite-day is one call, :func:`compute_day`, whose :class:`DayWork` the service records; the day's
LOS fingerprint comes with it as a :class:`DayFingerprint`, compared with the stored :class:`DayPrint` of
the day before.
"""

from monitor.assessment.assess import DayAssessment
from monitor.assessment.day import Assessor, DayWork, NoRoom, ProgressLines, RunCounts, compute_day
from monitor.mapping.fingerprint import DayFingerprint, DayPrint

__all__ = [
    "Assessor",
    "DayAssessment",
    "DayFingerprint",
    "DayPrint",
    "DayWork",
    "NoRoom",
    "ProgressLines",
    "RunCounts",
    "compute_day",
]
