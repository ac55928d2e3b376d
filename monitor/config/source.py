"""The ``source`` section: where granules come from (NODD, a folder, the simulator) and the bounds of every
read."""

from __future__ import annotations

import re
from typing import Annotated, Any

from pydantic import (
    BeforeValidator,
    model_validator,
)

from monitor.config.keys import FilePath, KeyProblem, Section, Text, Url, key
from monitor.core.satellites import SATELLITES
from monitor.core.vocabulary import (
    ReadMode,
    SourceKind,
)

NODD_BUCKETS = {s.short: s.bucket for s in SATELLITES.values()}


BUCKET = re.compile(r"[a-z0-9][a-z0-9.-]{1,61}[a-z0-9]", re.ASCII)


def _buckets(value: Any) -> Any:
    """The published bucket of every satellite, those given replacing theirs."""
    return {**NODD_BUCKETS, **value} if isinstance(value, dict) else value


class CalibrationDifference(Section):
    """A simulated CrIS-VIIRS calibration difference (``source.calibration.SATELLITE``): the BT CrIS reports
    is T + bias_k + gain (T - 280 K) + nonlinear_k ((T - 280 K) / 30 K)^2."""

    bias_k: float = key(0.0, "CrIS minus VIIRS BT at 280 K.", -5, 5)
    gain: float = key(
        0.0, "Relative gain difference (0.01: CrIS BT departs 1 % of T - 280 K more).", -0.1, 0.1
    )
    nonlinear_k: float = key(0.0, "Quadratic term, its value 30 K from 280 K.", -5, 5)


class SourceConfig(Section):
    """The ``source`` section: where granules come from, and the bounds of every request to NODD."""

    kind: SourceKind = key(
        ...,
        strict=False,
        meaning="Where granules come from: nodd (NOAA's archive on S3), local (a directory tree) "
        "or simulated (the offline demo).",
    )
    path: FilePath | None = key(
        None, "Root of the local tree (kind local); every *.h5 below it is considered."
    )
    endpoint: Url = key(
        "https://{bucket}.s3.amazonaws.com",
        "NODD URL template; {bucket} is replaced by the satellite's bucket.",
    )
    buckets: Annotated[dict[str, Text], BeforeValidator(_buckets)] = key(
        dict(NODD_BUCKETS), "NODD bucket per satellite (mapping); keys not given keep the published buckets."
    )
    read: ReadMode = key(
        ReadMode.RANGES,
        "How NODD granules are read: ranges (in place, only the datasets and scans the day needs, "
        "through a block cache on disk) or whole (each file downloaded whole first).",
    )
    timeout_s: float = key(
        60.0,
        "Wall-clock bound of a listing page (body included) and of the headers of any "
        "answer; also the socket timeout.",
        0.1,
        3600,
    )
    retries: int = key(5, "Retries of a failed request (backoff doubling from backoff_s).", 0, 20)
    backoff_s: float = key(1.5, "First wait between retries.", 0.01, 600)
    daily_budget_mb: float = key(
        6000.0,
        "Most bytes downloaded in one satellite-day run (whole files or ranges); what would exceed it is "
        "skipped with the reason.",
        1,
        1e6,
    )
    retention_days: int = key(
        7,
        "Downloaded files older than this are removed from the cache at the start of a "
        "run (kind simulated: this many simulated days are kept).",
        0,
        3650,
    )
    cache_max_mb: float = key(
        20000.0,
        "Before every run the least recently used files go until the cache holds at most this (downloads, "
        "and the blocks of files read in place; a run adds at most daily_budget_mb).",
        0,
        1e8,
    )
    run_deadline_min: float = key(
        180.0, "Every request of one satellite-day run ends by this time after the run started.", 1, 1440
    )
    max_list_pages: int = key(
        100, "Most pages of one listing (a day of one product is ~3 pages of 1000 keys).", 1, 10000
    )
    max_listed_keys: int = key(20000, "Most keys of one listing.", 1, 10**6)
    max_retry_after_s: float = key(
        120.0, "A server asking to wait longer than this (Retry-After) ends the attempt.", 1, 3600
    )
    min_rate_kb_s: float = key(
        50.0, "A download that brings less than this over any stall_window_s is cut (and retried).", 1, 1e6
    )
    stall_window_s: float = key(
        30.0,
        "The sliding window over which a download must keep up min_rate_kb_s; a "
        "silence this long cuts it too.",
        1,
        3600,
    )
    granules: int = key(4, "Consecutive CrIS granules simulated per satellite-day (kind simulated).", 1, 100)
    profile: Text = key(
        "paper", "Error profile injected by the simulator (paper, random, zero or a file; kind simulated)."
    )
    seed: int = key(0, "Seed of the simulator (kind simulated).", 0, 2**31 - 1)
    calibration: dict[str, CalibrationDifference] = key(
        {},
        "CrIS-VIIRS calibration difference simulated per satellite (kind simulated; mapping of the keys "
        "below); none: the instruments agree.",
        json_schema_extra={"x-key": "satellite"},
    )

    @model_validator(mode="after")
    def _consistent(self) -> SourceConfig:
        if "{bucket}" not in self.endpoint:
            raise KeyProblem("endpoint", f"{self.endpoint!r} has no {{bucket}} placeholder")
        for sat in self.calibration:
            if sat not in SATELLITES:
                raise KeyProblem(f"calibration.{sat}", f"not one of {', '.join(SATELLITES)}")
        for sat, bucket in self.buckets.items():
            if sat not in SATELLITES:
                raise KeyProblem(f"buckets.{sat}", f"not one of {', '.join(SATELLITES)}")
            if not BUCKET.fullmatch(bucket):
                raise KeyProblem(f"buckets.{sat}", f"{bucket!r} is not a bucket name")
        if self.kind == SourceKind.LOCAL:
            if self.path is None:
                raise KeyProblem("path", "missing")
            if not self.path.is_dir():
                raise KeyProblem("path", f"{self.path} is not a directory")
        return self
