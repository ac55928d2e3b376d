"""What every section is made of: the key declaration, the value types (paths, URLs, secrets' names, times,
addresses) and their checks, the one-line errors, secrets read and URLs redacted."""

from __future__ import annotations

import datetime as dt
import os
import re
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any
from urllib.parse import urlsplit, urlunsplit

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    ValidationInfo,
    WithJsonSchema,
)

from monitor.core.bands import BANDS


class ConfigError(ValueError):
    """A configuration problem, naming the key."""


class KeyProblem(ValueError):
    """Raised by a section's own checks: the problem of a key (relative to the section).

    Parameters
    ----------
    key : str
        The key.
    problem : str
        What is wrong.
    """

    def __init__(self, key: str, problem: str):
        super().__init__(problem)
        self.key = key


def _no_nul(text: str) -> str:
    if "\x00" in text:
        raise ValueError("contains a NUL character")
    return text


def _path(value: Any, info: ValidationInfo) -> Path:
    """A path from the file: ``~`` and ``$VARS`` expanded, relative to the file's folder."""
    if not isinstance(value, str):
        raise ValueError(f"expected a path, got {type(value).__name__} {str(value)[:60]!r}")
    _no_nul(value)
    p = Path(os.path.expandvars(value)).expanduser()
    base = (info.context or {}).get("base")
    return p if p.is_absolute() or base is None else base / p


def _url(value: str) -> str:
    """An http(s) URL without credentials in it (secrets come from *_env variables)."""
    try:
        parts = urlsplit(value)
    except ValueError:
        raise ValueError(f"{value!r} is not a URL") from None
    if parts.scheme not in ("http", "https") or not parts.netloc:
        raise ValueError(f"{redact_url(value)!r} is not an http(s) URL")
    if parts.username or parts.password or "@" in parts.netloc:
        raise ValueError(
            "credentials may not be written in a URL; name environment variables with the *_env keys"
        )
    return value.rstrip("/")


ENV_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,127}", re.ASCII)


def _env_name(value: str) -> str:
    if not ENV_NAME.fullmatch(value):
        raise ValueError("a value is not the name of an environment variable")
    return value


def _hhmm(value: Any) -> dt.time:
    if isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 24 * 60:
        # YAML 1.1 reads an unquoted 3:30 as a base-60 number
        raise ValueError(
            f"{value} is not HH:MM (YAML reads an unquoted {value // 60}:{value % 60:02d} as the number "
            f"{value}: quote it, '{value // 60:02d}:{value % 60:02d}')"
        )
    m = re.fullmatch(r"(\d{1,2}):(\d{2})", value, re.ASCII) if isinstance(value, str) else None
    if not m or int(m[1]) > 23 or int(m[2]) > 59:
        raise ValueError(f"{value!r} is not HH:MM")
    return dt.time(int(m[1]), int(m[2]))


def _address(value: str) -> str:
    if "@" not in value:
        raise ValueError(f"{value!r} is not an address")
    return value


Text = Annotated[str, AfterValidator(_no_nul)]


FilePath = Annotated[Path, BeforeValidator(_path), WithJsonSchema({"type": "string"})]


Url = Annotated[
    str, AfterValidator(_no_nul), AfterValidator(_url), WithJsonSchema({"type": "string", "format": "uri"})
]


EnvName = Annotated[
    str, AfterValidator(_env_name), WithJsonSchema({"type": "string", "pattern": ENV_NAME.pattern})
]


Address = Annotated[str, AfterValidator(_no_nul), AfterValidator(_address)]


def _band(value: str) -> str:
    if value not in BANDS:
        raise ValueError(f"{value!r} is not one of {', '.join(BANDS)}")
    return value


Band = Annotated[str, AfterValidator(_band), WithJsonSchema({"type": "string", "enum": list(BANDS)})]


TimeOfDay = Annotated[
    dt.time,
    BeforeValidator(_hhmm),
    PlainSerializer(lambda t: t.strftime("%H:%M"), return_type=str),
    WithJsonSchema({"type": "string", "pattern": r"^\d{1,2}:\d{2}$"}),
]


def key(default: Any, meaning: str, lo: float | None = None, hi: float | None = None, **kw: Any) -> Any:
    """A configuration key: its default, meaning and accepted range.

    Parameters
    ----------
    default : object
        Its default; ``...``: required; a section class: that section's defaults.
    meaning : str
        What it means (the reference and the JSON Schema's description).
    lo, hi : float, optional
        The accepted range, inclusive, in the unit its name ends in.
    **kw : object
        Passed to pydantic's ``Field``.

    Returns
    -------
    pydantic.fields.FieldInfo
        The declaration.
    """
    if isinstance(default, type):
        return Field(default_factory=default, description=meaning, **kw)
    if isinstance(default, StrEnum):
        kw.setdefault("strict", False)  # the file holds the member's string
    return Field(default, description=meaning, ge=lo, le=hi, **kw)


class Section(BaseModel):
    """A section of the file: known keys only, exact types (no '5' for 5, no true for 1), finite numbers."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, validate_assignment=False)


def parse_listen(text: str) -> tuple[str, int]:
    """``HOST:PORT`` (``[::1]:PORT`` for IPv6) as host and port.

    Parameters
    ----------
    text : str
        The address.

    Returns
    -------
    host : str
        The host.
    port : int
        The port; a ValueError names the value otherwise.
    """
    host, sep, port = str(text).rpartition(":")
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ValueError(f"{text!r} is not HOST:PORT")
    return host, int(port)


def check_listen(text: str) -> str:
    """``off`` or ``HOST:PORT`` (the daemon's HTTP endpoint).

    Parameters
    ----------
    text : str
        The value.

    Returns
    -------
    str
        It, checked; a ValueError otherwise.
    """
    if text != "off":
        try:
            parse_listen(text)
        except ValueError as exc:
            raise ValueError(f"{exc} (or off)") from None
    return text


def env_secret(name: str | None) -> str | None:
    """The secret a ``*_env`` key names: the environment variable of that name, else the systemd credential
    of that name (``LoadCredential=NAME:/path`` in the unit: the file ``$CREDENTIALS_DIRECTORY/NAME``,
    systemd.exec(5)), its trailing newline removed.

    Parameters
    ----------
    name : str or None
        The variable (and credential) name.

    Returns
    -------
    str or None
        Its value; None when neither is set, or unnamed.
    """
    if not name:
        return None
    if name in os.environ:
        return os.environ[name]
    folder = os.environ.get("CREDENTIALS_DIRECTORY")
    if folder and "/" not in name:
        try:
            return (Path(folder) / name).read_text().rstrip("\n")
        except OSError:
            return None
    return None


def redact_url(url: str) -> str:
    """A URL with any user:password and query string masked, for logs and messages.

    Parameters
    ----------
    url : str
        The URL.

    Returns
    -------
    str
        The masked URL.
    """
    try:
        p = urlsplit(str(url))
    except ValueError:
        return "<unparsable URL>"
    netloc = p.netloc.rsplit("@", 1)[-1]
    if "@" in p.netloc:
        netloc = "***@" + netloc
    return urlunsplit((p.scheme, netloc, p.path, "***" if p.query else "", ""))
