"""Where results go: ``store`` (SQLite, the time-series databases), ``http`` (the daemon's endpoint),
``export`` (NetCDF publisher attributes)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import (
    AfterValidator,
)

from monitor.config.keys import EnvName, FilePath, Section, Text, Url, check_listen, env_secret, key
from monitor.core.vocabulary import (
    PublishKind,
)


class ExportConfig(Section):
    """The ``export`` section: who publishes the exported NetCDF (ACDD 1.3 discovery attributes); a key
    left out leaves its attribute out."""

    institution: Text | None = key(None, "ACDD institution: the organisation that runs the monitor.")
    creator_name: Text | None = key(None, "ACDD creator_name: the team or person who made the data.")
    creator_email: Text | None = key(None, "ACDD creator_email: where users write about the data.")
    creator_url: Url | None = key(None, "ACDD creator_url: the team's page.")
    license: Text | None = key(None, "ACDD license: the terms of use (e.g. an SPDX identifier, CC0-1.0).")
    naming_authority: Text | None = key(
        None, "ACDD naming_authority, reverse DNS (gov.noaa.star); a file's id is unique within it."
    )
    project: Text | None = key(None, "ACDD project: the programme the data serve (e.g. JPSS).")


class HttpConfig(Section):
    """The ``http`` section."""

    listen: Annotated[Text, AfterValidator(check_listen)] = key(
        "127.0.0.1:9782",
        "HOST:PORT of /metrics, /healthz and /report/ (loopback by default; port 0: any free "
        "port; off: no endpoint). crisgeo daemon --listen overrides it.",
    )


class PublishConfig(Section):
    """One entry of ``store.publish``: a time-series database the results are written to."""

    kind: PublishKind = key(
        ...,
        strict=False,
        meaning="influx2 (InfluxDB 2 API: token) or influx1 (InfluxDB 1 / VictoriaMetrics: user, password).",
    )
    url: Url = key(..., "Base URL of the database (no credentials in it).")
    measurement: Text = key("cris_geolocation", "Measurement name of the points.")
    bucket: Text = key("crisgeo", "Bucket (influx2).")
    org: Text = key("-", "Organisation (influx2).")
    token_env: EnvName | None = key(None, "Environment variable holding the token (influx2).")
    database: Text = key("crisgeo", "Database (influx1).")
    username_env: EnvName | None = key(None, "Environment variable holding the user name (influx1).")
    password_env: EnvName | None = key(None, "Environment variable holding the password (influx1).")
    timeout_s: float = key(30.0, "Timeout of one write.", 0.1, 600)

    def secret(self, name: str) -> str | None:
        """The value of the environment variable a key names (e.g. ``token_env``).

        Parameters
        ----------
        name : str
            The key.

        Returns
        -------
        str or None
            Its value, or None.
        """
        return env_secret(getattr(self, name))


class StoreConfig(Section):
    """The ``store`` section."""

    sqlite: FilePath | None = key(
        None, "The SQLite store (history, alert state, outbox). Default: state_dir/crisgeo.sqlite."
    )
    publish: list[PublishConfig] = key(
        [], "Time-series databases the results are written to (list of the mappings below)."
    )
    drain_minutes: float = key(
        10.0, "The daemon sends the time-series points waiting in the outbox this often.", 0.01, 1440
    )

    @property
    def path(self) -> Path:  # numpydoc ignore=RT01
        """The store's file (filled in by :class:`Config`)."""
        assert self.sqlite is not None, "store.sqlite is filled in when the configuration is loaded"
        return self.sqlite
