"""The ``alerts`` section: the rules' thresholds, the channels (e-mail, Slack, Alertmanager), the links in
messages."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Annotated, Any

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    PrivateAttr,
    model_validator,
)

from monitor.config.keys import Address, EnvName, FilePath, KeyProblem, Section, Text, Url, key
from monitor.core.constants import REFERENCE_ALTITUDE_M, SPEC_KM, URAD

LOG = logging.getLogger(__name__)
# the earlier jump rule's keys: what became of each
RETIRED = {
    "min_jump_km": "read as practical_step_urad",
    "jump_z": "the blind test's threshold comes from false_detections_per_year",
    "jump_z_at_change": "the threshold at a known change comes from false_detection_at_change",
    "min_post_days": "a step is tried from its first day on (discovery_days)",
    "blind_window_days": "discovery_days says how long a step is tried after its date",
    "change_window_days": "a known change is tried in the discovery_days after it",
}


class RuleSettings(Section):
    """The alert rules' parameters: the top-level keys of the ``alerts`` section."""

    spec_km: float = key(
        SPEC_KM,
        "Specification of the geolocation error on the ground; a reliable FOR beyond it "
        "fires the spec rule (critical when value - 2 sigma is beyond it).",
        0.01,
        100.0,
    )
    false_detections_per_year: float = key(
        1.0,
        "Steps the jump rules may find per satellite-year on a stable instrument, on days without a known "
        "change (recorded or paged): their blind test's threshold comes from it.",
        0.01,
        365.0,
    )
    false_detection_at_change: float = key(
        0.05,
        "Chance that a known change which moved nothing is found as a step at its date: the threshold of "
        "the test at a known change.",
        0.0001,
        0.5,
    )
    practical_step_urad: float = key(
        50.0,
        "Smallest LOS step (pooled over the FORs that found it) that is paged; a smaller one is recorded and "
        "shown (severity info), not sent.",
        0.0,
        100000.0,
    )
    min_bias_jump_k: float = key(
        0.05,
        "Smallest step of the daily CrIS-VIIRS BT bias at 280 K (pooled over the FORs that found it) that "
        "the calibration_jump rule pages (a VIIRS LUT or CrIS calibration change), and of each band's "
        "daily CrIS minus VIIRS difference; a smaller one is recorded. Half the 0.1 K step it must see.",
        0.0,
        100.0,
    )
    radiometry_limit_k: float = key(
        0.5,
        "A FOR whose daily CrIS minus VIIRS difference in a band (cris_minus_viirs_k_<BAND>) is beyond this "
        "in magnitude pages, as the specification does: critical where it is beyond it by 2 sigma, K.",
        0.0,
        100.0,
    )
    pre_days: int = key(
        21,
        "The baseline: days before a candidate step that form the reference; a step's alert resolves once "
        "its new level has held this long.",
        2,
        365,
    )
    min_pre_days: int = key(7, "Fewest assessed baseline days for a step to be tested.", 2, 365)
    discovery_days: int = key(
        3, "Days after a step (its first day included) within which the blind test tries it.", 1, 14
    )
    post_days: int = key(14, "Days after a step its size per FOR is measured over.", 1, 365)
    attribution_days: int = key(
        1,
        "A step is attributed to a known change whose day is at most this many days from its date (the "
        "date is found within a day).",
        0,
        365,
    )
    active_days: int = key(14, "A processing change older than this no longer fires.", 1, 3650)
    stale_hours: float = key(36.0, "No completed run for this long fires the stale rule.", 1.0, 8760.0)
    repeat_hours: float = key(24.0, "A firing alert is notified again after this long.", 0.1, 8760.0)

    @model_validator(mode="before")
    @classmethod
    def _retired(cls, data: Any) -> Any:
        """Keys of the earlier jump rule, read with a warning: ``min_jump_km`` as ``practical_step_urad`` (at
        nadir), the z thresholds and windows ignored (the thresholds come from the false-detection rates)."""
        if not isinstance(data, dict) or not RETIRED.keys() & data.keys():
            return data
        data = dict(data)
        if "min_jump_km" in data:
            km = data.pop("min_jump_km")
            if isinstance(km, int | float) and "practical_step_urad" not in data:
                data["practical_step_urad"] = float(km) * 1000.0 / REFERENCE_ALTITUDE_M / URAD
                LOG.warning(
                    "alerts.min_jump_km (%s km) is read as alerts.practical_step_urad %.0f (at nadir); "
                    "rename it",
                    km,
                    data["practical_step_urad"],
                )
        for name in RETIRED.keys() & data.keys():
            data.pop(name)
            LOG.warning("alerts.%s is no longer used: %s; remove it", name, RETIRED[name])
        return data

    @model_validator(mode="after")
    def _consistent(self) -> RuleSettings:
        if self.min_pre_days > self.pre_days:
            raise KeyProblem(
                "min_pre_days", f"{self.min_pre_days} is more than alerts.pre_days ({self.pre_days})"
            )
        return self


class EmailSettings(Section):
    """The ``alerts.email`` section."""

    model_config = ConfigDict(populate_by_name=True, serialize_by_alias=True)

    host: Text = key(..., "SMTP server.")
    port: int = key(587, "SMTP port.", 1, 65535)
    sender: Address = key("crisgeo@localhost", "Sender address.", alias="from")
    to: Annotated[list[Address], Field(min_length=1)] = key(..., "Recipient addresses (list).")
    starttls: bool = key(True, "Use STARTTLS (certificate verified against the system store, or cafile).")
    username_env: EnvName | None = key(None, "Environment variable holding the SMTP user name.")
    password_env: EnvName | None = key(None, "Environment variable holding the SMTP password.")
    cafile: FilePath | None = key(None, "Extra CA bundle (e.g. a site CA) to verify the server with.")
    timeout_s: float = key(30.0, "Timeout of one SMTP conversation.", 0.1, 600.0)


class SlackSettings(Section):
    """The ``alerts.slack`` section."""

    webhook_env: EnvName = key(..., "Environment variable holding the incoming-webhook URL.")
    retries: int = key(3, "Retries when Slack answers 429 or 5xx.", 0, 20)
    max_wait_s: float = key(30.0, "Longest wait honoured from a Retry-After header.", 0.0, 3600.0)
    timeout_s: float = key(15.0, "Timeout of one request.", 0.1, 600.0)


class AlertmanagerSettings(Section):
    """The ``alerts.alertmanager`` section: where the service posts its alerts (Alertmanager API v2)."""

    url: Url = key(..., "Base URL of Alertmanager, e.g. http://127.0.0.1:9093.")
    timeout_s: float = key(10.0, "Timeout of one post.", 0.1, 600.0)
    validity_hours: float = key(
        3.0,
        "A firing alert is posted again at every evaluation (hourly, and after each "
        "run) with this end; if the service stops posting, Alertmanager ends it then.",
        1.5,
        168.0,
    )


class Links(BaseModel):
    """Where readers of a message find more: the top-level report_dir, report_url and dashboard_url."""

    report_dir: Path | None = None
    report_url: str | None = None
    dashboard_url: str | None = None


class AlertSettings(RuleSettings):
    """The ``alerts`` section: the rule parameters, the channels and the events calendar."""

    subject_prefix: Text = key(
        "[crisgeo]",
        "Start of every message's subject (e-mail subject, Slack headline): e.g. [crisgeo test] for a test "
        "instance, so that its messages are not taken for the operational service's.",
    )
    log: FilePath | None = key(None, "File the alert messages are appended to (a channel that cannot fail).")
    events_file: FilePath | None = key(
        None, "The events calendar (EP uploads, LUT changes) used to attribute jumps and annotate plots."
    )
    email: EmailSettings | None = key(None, "E-mail channel (mapping below); absent: none.")
    slack: SlackSettings | None = key(None, "Slack channel (mapping below); absent: none.")
    alertmanager: AlertmanagerSettings | None = key(
        None,
        "Alertmanager (mapping below): the alerts are posted to its API v2 with labels alertname, service, "
        "satellite, rule, severity and resolved there, so that Alertmanager routes, groups and silences "
        "them; absent: none.",
    )
    _links: Links = PrivateAttr(default_factory=Links)

    def linked(self, links: Links) -> AlertSettings:
        """These settings, pointing their messages at the report and dashboard.

        Parameters
        ----------
        links : Links
            The top-level ``report_dir``, ``report_url`` and ``dashboard_url``.

        Returns
        -------
        AlertSettings
            The same settings, linked.
        """
        self._links = links
        return self

    @property
    def links(self) -> Links:  # numpydoc ignore=RT01
        """The report and dashboard the messages point to (the top-level keys)."""
        return self._links

    @property
    def channels(self) -> list[str]:  # numpydoc ignore=RT01
        """The names of the configured channels."""
        return [n for n in ("log", "email", "slack") if getattr(self, n)]
