"""The service's shared words, at the ground floor: every module that speaks of runs, events, rules or
severities imports them from here (the store, the alerts, the pipeline, the metrics, the CLI).

Each is a ``StrEnum``: its members are the strings stored in SQLite, written in messages and labels, and
compared with plain strings where those come back.
"""

from __future__ import annotations

from enum import StrEnum


class RunStatus(StrEnum):
    """The status of a run in the ledger (the string stored)."""

    RUNNING = "running"
    OK = "ok"  # results stored
    NO_DATA = "no_data"  # nothing to assess yet: tried again for schedule.no_data_retry_days
    NO_DATA_FINAL = "no_data_final"  # nothing to assess, for good
    FAILED = "failed"
    INTERRUPTED = "interrupted"  # a stop request or a killed process: redone at the next run


DONE = (RunStatus.OK, RunStatus.NO_DATA, RunStatus.NO_DATA_FINAL)  # a day with one of these is not redone


class EventKind(StrEnum):
    """What an ``events`` row records."""

    RUN_FAILED = "run_failed"  # detail: day, reason
    JOB_ERROR = "job_error"  # detail: job, error, scheduled (a scheduler job raised)
    JOB_MISSED = "job_missed"  # ... was missed (the host was down past the misfire grace)
    JOB_SKIPPED = "job_skipped"  # ... was skipped (the previous instance still ran)
    CHANGE_CRIS = "change:cris"  # detail: time, kind, description, origin (a CrIS processing change)
    CHANGE_VIIRS = "change:viirs"  # the same for VIIRS

    @property
    def is_change(self) -> bool:  # numpydoc ignore=RT01
        """Whether the event records a processing change (change:<instrument>)."""
        return self.value.startswith("change:")


SCHEDULER_KINDS = (EventKind.JOB_ERROR, EventKind.JOB_MISSED, EventKind.JOB_SKIPPED)


class Rule(StrEnum):
    """The alert rules (alerts/rules.py), by the name stored, shown and silenced."""

    SPEC = "spec"  # an error beyond the specification
    JUMP = "jump"  # a step in the offsets, attributed to a known change where there is one
    CALIBRATION_JUMP = (
        "calibration_jump"  # a step in a band's CrIS-VIIRS BT difference, attributed the same way
    )
    RADIOMETRY = "radiometry"  # a band's CrIS-VIIRS BT difference beyond its limit
    STALE = "stale"  # no successful assessment for too long
    FAILURE = "failure"  # failed or missed runs
    PROCESSING = "processing"  # a change seen in the GEO files' LOS fingerprint


class Severity(StrEnum):
    """How urgent an alert is."""

    INFO = "info"  # recorded and shown, never sent (a step below the practical size)
    WARNING = "warning"
    CRITICAL = "critical"


class AlertStatus(StrEnum):
    """The state of an alert in the store (a silence is kept apart: it quiets, it does not change this)."""

    FIRING = "firing"
    RESOLVED = "resolved"


class Notice(StrEnum):
    """Why an alert is in a message: it started, it still fires after ``repeat_hours``, or it ended."""

    FIRING = "firing"
    REPEAT = "repeat"
    RESOLVED = "resolved"


class DeliveryStatus(StrEnum):
    """The state of a queued message on one channel."""

    PENDING = "pending"  # waiting for its (next) attempt
    SENDING = "sending"  # claimed by a sender (a lease: a sender that died leaves it to be tried again)
    SENT = "sent"
    FAILED = "failed"  # for good: a configuration error, or the channel is gone


class BinnedBy(StrEnum):
    """What a day's CrIS minus VIIRS differences are binned by (``RadiometryBin``, monitor/core/result.py)."""

    FOV = "fov"  # the CrIS FOV, 1..9
    SCENE = "scene_k"  # the scene's VIIRS BT, in bins of 10 K
    NODE = "node"  # the orbit's ascending or descending node


class Kernel(StrEnum):
    """The CrIS footprint weighting of the collocation (``assessment.kernel``)."""

    TOP_HAT = "top-hat"  # the paper: every VIIRS pixel inside the FOV's circle counts alike
    FOOTPRINT = (
        "footprint"  # the FOV's radially symmetric response fitted over annuli (monitor.estimation.estimate)
    )


class SourceKind(StrEnum):
    """Where granules come from (``source.kind``)."""

    NODD = "nodd"  # NOAA's archive on S3
    LOCAL = "local"  # a directory tree
    SIMULATED = "simulated"  # the offline demo


class ReadMode(StrEnum):
    """How NODD granules are read (``source.read``)."""

    RANGES = "ranges"  # in place: only the bytes the day needs, through a block cache on disk
    WHOLE = "whole"  # every file downloaded whole to the cache first


class PublishKind(StrEnum):
    """The protocol of a time-series database (``store.publish[].kind``)."""

    INFLUX2 = "influx2"  # InfluxDB 2 API, token
    INFLUX1 = "influx1"  # InfluxDB 1 API (also VictoriaMetrics), user and password


class Decision(StrEnum):
    """What scene selection decided for a CrIS granule of the day."""

    CHOSEN = "chosen"
    REJECTED = "rejected"
    NOT_CONSIDERED = "not considered"  # outside the candidates spread over the day


class Cost(StrEnum):
    """The cost whose minimum over the perturbations is the geolocation offset (``assessment.cost``)."""

    STDEV = "stdev"  # the paper's equation (8): STDEV(BT_VIIRS - BT_CrIS)
    REGRESSION = "regression"  # the residual STDEV of BT_VIIRS - BT_CrIS regressed on BT_CrIS


# equal to the paper's where CrIS and VIIRS agree, unmoved where their calibrations differ (docs/science.md,
# "Cost and minimum")
DEFAULT_COST = Cost.REGRESSION
# the default footprint weighting: the response fitted over annuli, which a real CrIS FOV's smooth response
# cannot bias (docs/science.md, "The CrIS footprint")
DEFAULT_KERNEL = Kernel.FOOTPRINT


class DayStop(StrEnum):
    """Why a satellite-day stopped assessing granules (``scenes.target_sigma_urad``, docs/operations.md)."""

    ONE_BATCH = "one batch"  # no target: the scenes.keep most informative granules, as the paper
    TARGET = "target reached"  # the day's sigma reached scenes.target_sigma_urad
    MAX_GRANULES = "max_granules"  # scenes.max_granules assessed
    CANDIDATES = "candidates spent"  # every usable candidate assessed
    BYTES = "byte budget"  # the next batch would pass source.daily_budget_mb
    TIME = "time budget"  # the next batch would pass schedule.run_budget_min
