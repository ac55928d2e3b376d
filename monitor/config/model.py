"""The whole configuration: its sections (a module each) and the keys of the top level."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

from pydantic import (
    AfterValidator,
    Field,
    PrivateAttr,
    model_validator,
)

from monitor.config.alert_settings import AlertSettings, Links
from monitor.config.assessment import AssessmentConfig, FingerprintConfig, SceneConfig
from monitor.config.keys import Band, FilePath, KeyProblem, Section, Url, key
from monitor.config.outputs import ExportConfig, HttpConfig, StoreConfig
from monitor.config.schedule import ScheduleConfig
from monitor.config.source import SourceConfig
from monitor.core.bands import BANDS
from monitor.core.satellites import SATELLITES


def _satellite(value: str) -> str:
    if value not in SATELLITES:
        raise ValueError(f"{value!r} is not one of {', '.join(SATELLITES)}")
    return value


class Config(Section):
    """The whole configuration, validated."""

    satellites: Annotated[list[Annotated[str, AfterValidator(_satellite)]], Field(min_length=1)] = key(
        ..., "Satellites to monitor, short names (npp, j01, j02)."
    )
    state_dir: FilePath = key(
        ...,
        "Directory of the service's state: store, download cache, simulated granules, "
        "lock. Relative paths in the file are relative to the file.",
    )
    min_free_mb: int = key(
        2000,
        "Room a satellite-day needs on state_dir's file system (downloads, block cache, simulated granules, "
        "the store); a run that finds less ends before it starts, recorded failed and redone once there is "
        "room.",
        0,
        10**7,
    )
    source: SourceConfig = key(..., "Where granules come from (the keys below).")
    schedule: ScheduleConfig = key(ScheduleConfig, "When the daemon runs (the keys below).")
    scenes: SceneConfig = key(SceneConfig, "Which granules are assessed (the keys below).")
    assessment: AssessmentConfig = key(
        AssessmentConfig, "The perturbation grid and collocation (the keys below)."
    )
    fingerprint: FingerprintConfig = key(FingerprintConfig, "The LOS fingerprint (the keys below).")
    http: HttpConfig = key(HttpConfig, "The daemon's HTTP endpoint (the key below).")
    export: ExportConfig = key(ExportConfig, "Publisher attributes of exported NetCDF (the keys below).")
    store: StoreConfig = key(StoreConfig, "Where results are kept and published (the keys below).")
    alerts: AlertSettings = key(AlertSettings, "Alert rules and channels (the keys below).")
    report_dir: FilePath | None = key(
        None,
        "Where the HTML report is regenerated after every run (and served under /report/). None: no report.",
    )
    report_url: Url | None = key(
        None,
        "The address at which readers open report_dir (e.g. behind a reverse "
        "proxy); messages link REPORT_URL/SATELLITE/. Without it they name the path on "
        "the server.",
    )
    dashboard_url: Url | None = key(None, "Link to the Grafana dashboard, added to every message.")
    mapping_dir: FilePath | None = key(
        None,
        "Where the daily run writes each day's mapping, as the command crisgeo map writes it (every assessed "
        "CrIS FOV's VIIRS scene and CrIS BT per band, on the day's assessed geolocation), as "
        "SATELLITE/SATELLITE_DAY.nc. None: no mapping.",
    )
    mapping_bands: Annotated[list[Band], Field(min_length=1)] = key(
        list(BANDS), "The VIIRS bands of the day's mapping (I5, M13, M15, M16)."
    )
    _file: Path | None = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _consistent(self) -> Config:
        if len(set(self.satellites)) != len(self.satellites):
            raise KeyProblem("satellites", "a satellite is listed twice")
        _check_creatable(self.state_dir, "state_dir")
        calendar = self.alerts.events_file
        if calendar is not None and not calendar.is_file() and not _under(calendar, self.state_dir):
            # read as empty, a missing calendar would lose jump attribution without a word; one under the
            # state directory is the service's own, begun by the first `crisgeo events add`
            raise KeyProblem(
                "alerts.events_file",
                f"{calendar} does not exist (copy configs/events.yaml there, or remove the key)",
            )
        if self.mapping_dir is not None:
            _check_creatable(self.mapping_dir, "mapping_dir")
        if self.store.sqlite is None:
            self.store.sqlite = self.state_dir / "crisgeo.sqlite"
        self.alerts.linked(
            Links(report_dir=self.report_dir, report_url=self.report_url, dashboard_url=self.dashboard_url)
        )
        return self

    @property
    def path(self) -> Path | None:  # numpydoc ignore=RT01
        """The file the configuration was loaded from."""
        return self._file

    @property
    def events_file(self) -> Path | None:  # numpydoc ignore=RT01
        """The events calendar (``alerts.events_file``): attribution of jumps, annotations, the report."""
        return self.alerts.events_file

    @property
    def viirs_bands(self) -> tuple[str, ...]:  # numpydoc ignore=RT01
        """The VIIRS bands a day needs: I5 (the assessment's), the radiometry's (``assessment.bands``) and
        the mapping's when it is on."""
        wanted = {"I5", *self.assessment.bands, *(self.mapping_bands if self.mapping_dir is not None else ())}
        return tuple(b for b in BANDS if b in wanted)

    @property
    def cache_dir(self) -> Path:  # numpydoc ignore=RT01
        """Where downloads are cached: ``state_dir/cache``."""
        return self.state_dir / "cache"


def _under(path: Path, folder: Path) -> bool:
    return path.resolve().is_relative_to(folder.resolve())


def _check_creatable(path: Path, where: str) -> None:
    """*path* is a directory, or can be made one: its nearest existing ancestor is a writable directory
    on a file system that holds files (not /proc or /sys). Nothing is created."""
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe == path and not path.is_dir():
        raise KeyProblem(where, f"{path} exists and is not a directory")
    if not probe.is_dir() or not os.access(probe, os.W_OK | os.X_OK):
        raise KeyProblem(where, f"{path} cannot be created ({probe} is not a writable directory)")
    if probe != path and os.statvfs(probe).f_blocks == 0:  # proc, sysfs and the like: no room for files
        raise KeyProblem(where, f"{path} cannot be created ({probe} is a virtual file system)")
