"""The configuration file: YAML read safely (no anchors, aliases or duplicate keys, 1 MiB at most), validated
by the model of :mod:`monitor.config.model`, and every problem said in one line naming the key
(``store.publish[0].url: missing``); the effective configuration printed back, with its secrets' state, and
the JSON Schema editors validate YAML with.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import yaml
import yaml.events
from pydantic import BaseModel, ValidationError

from monitor.config.keys import ConfigError, KeyProblem, env_secret
from monitor.config.model import Config
from monitor.core.vocabulary import SourceKind

# -- loading


def load_config(path: str | Path) -> Config:
    """Load and validate the YAML configuration; relative paths are relative to the file.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    Config
        The configuration; any problem is a :class:`ConfigError` naming the key, in one line.
    """
    path = Path(path)
    doc = read_yaml(path)
    if not isinstance(doc, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level")
    _check_secrets(doc)
    try:
        cfg = Config.model_validate(doc, context={"base": path.resolve().parent})
    except ValidationError as exc:
        raise ConfigError(_one_line(exc)) from None
    cfg._file = path
    return cfg


def section_in_file(path: str | Path, name: str) -> BaseModel:
    """One section of a configuration file, checked as the whole file checks it; the other sections are
    not read (``crisgeo assess --config`` needs the assessment's settings, not the service's folders).

    Parameters
    ----------
    path : str or Path
        The file.
    name : str
        The section (``assessment``).

    Returns
    -------
    pydantic.BaseModel
        The section (its defaults where the file has none); any problem a :class:`ConfigError` naming the
        file and the key.
    """
    path = Path(path)
    doc = read_yaml(path)
    if not isinstance(doc, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level")
    values = doc.get(name) or {}
    if not isinstance(values, dict):
        raise ConfigError(f"{path}: {name}: expected a mapping, got {values!r}")
    try:
        return section_of(name, **values)
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None


def section_of(name: str, **values: Any) -> BaseModel:
    """A section of the configuration from values alone (the command line's options), checked as a file's.

    Parameters
    ----------
    name : str
        The section (``assessment``).
    **values : object
        Its keys.

    Returns
    -------
    pydantic.BaseModel
        The section; any problem a :class:`ConfigError` naming the key (``name.key: PROBLEM``).
    """
    model = _section_type(Config.model_fields[name].annotation)
    try:
        return model.model_validate(values)
    except ValidationError as exc:
        raise ConfigError(_one_line(exc, [name])) from None


def _one_line(exc: ValidationError, prefix: list | None = None) -> str:
    """The first problem of a validation, as ``KEY: PROBLEM``; *prefix*, where the validated model sits in
    the whole configuration."""
    err = exc.errors(include_url=False)[0]
    loc = [*(prefix or []), *err["loc"]]
    if err["type"] == "invalid_key":  # a key that is not a string (YAML reads 1: as an int)
        loc[-1] = str(loc[-1])
    problem = _problem(err, loc)
    cause = (err.get("ctx") or {}).get("error")
    if isinstance(cause, KeyProblem):
        loc += cause.key.split(".")
    return f"{_dotted(loc)}: {problem}" if loc else problem


def _dotted(loc: list) -> str:
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else f".{part}" if out else str(part)
    return out


_EXPECTED = {
    "int_type": "int",
    "float_type": "float",
    "string_type": "str",
    "bool_type": "bool",
    "list_type": "list",
    "tuple_type": "list",
}


def _problem(err: Any, loc: list) -> str:
    kind, value = err["type"], err.get("input")
    shown = f"{type(value).__name__} {str(value)[:60]!r}"
    if kind == "missing":
        return "missing"
    if kind in ("extra_forbidden", "invalid_key"):
        return f"unknown key (allowed: {', '.join(sorted(_model_at(loc[:-1]).model_fields))})"
    if kind in _EXPECTED:
        return f"expected {_EXPECTED[kind]}, got {shown}"
    if kind in ("dict_type", "model_type", "model_attributes_type"):
        return f"expected a mapping, got {shown}"
    if kind in ("greater_than_equal", "less_than_equal"):
        lo, hi = _bounds(loc)
        return f"{value} is not within {lo if lo is None else f'{lo:g}'}..{hi if hi is None else f'{hi:g}'}"
    if kind == "finite_number":
        return f"{value} is not a finite number"
    if kind == "too_short":
        return "empty" if not value else f"needs at least {err['ctx']['min_length']}"
    if kind == "enum":
        return f"{value!r} is not one of {err['ctx']['expected'].replace(chr(39), '').replace(' or ', ', ')}"
    if kind == "value_error":
        return str(err["ctx"]["error"])
    return str(err["msg"])


def _model_at(loc: list) -> type[BaseModel]:
    """The section model a location points into (list indices and mapping keys skipped)."""
    model: type[BaseModel] = Config
    keyed = False  # the last field was a mapping of sections: the next part is its key
    for part in loc:
        if isinstance(part, int) or keyed:
            keyed = False
            continue
        field = next(f for n, f in model.model_fields.items() if part in (n, f.alias))
        model = _section_type(field.annotation)
        keyed = getattr(field.annotation, "__origin__", None) is dict
    return model


def _section_type(annotation: Any) -> type[BaseModel]:
    """The section model in an annotation (``X``, ``X | None``, ``list[X]``)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()):
        try:
            return _section_type(arg)
        except TypeError:
            continue
    raise TypeError(f"no section in {annotation!r}")


def _bounds(loc: list) -> tuple[float | None, float | None]:
    """(lo, hi) of the key at *loc*."""
    field = _model_at(loc[:-1]).model_fields[str(loc[-1])]
    return key_range(field)


def key_range(field: Any) -> tuple[float | None, float | None]:
    """The range declared for a key (``key(..., lo, hi)``).

    Parameters
    ----------
    field : pydantic.fields.FieldInfo
        The key's declaration.

    Returns
    -------
    lo, hi : float or None
        Inclusive bounds, in the unit its name ends in; None where unbounded.
    """
    lo = next((m.ge for m in field.metadata if getattr(m, "ge", None) is not None), None)
    hi = next((m.le for m in field.metadata if getattr(m, "le", None) is not None), None)
    return lo, hi


def make_state_dir(cfg: Config) -> None:
    """Create the state directory, for the commands that write state.

    A ConfigError names the key when it cannot be made.

    Parameters
    ----------
    cfg : Config
        The configuration.
    """
    try:
        cfg.state_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"state_dir: cannot create {cfg.state_dir} ({exc.strerror or exc})") from None


SECRET_WORDS = re.compile(r"(token|password|secret|webhook)$", re.I)


def _check_secrets(doc: Any, where: str = "") -> None:
    """No secret written in the file: a key named like one (token, password, webhook) with a value is refused
    before anything else, whatever section it is in."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            if SECRET_WORDS.search(str(k)) and v not in (None, ""):
                raise ConfigError(
                    f"{where}{k}: secrets may not be written in the file; "
                    f"name an environment variable with {k}_env"
                )
            _check_secrets(v, f"{where}{k}.")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            _check_secrets(v, f"{where[:-1]}[{i}].")


# -- printing


def effective(cfg: Config) -> dict:
    """The configuration as loaded, defaults filled in, under the file's keys.

    Parameters
    ----------
    cfg : Config
        The configuration.

    Returns
    -------
    dict
        Written out as YAML it loads back to the same configuration (``crisgeo check-config`` prints it).
        Secrets are never in it: the ``*_env`` keys name variables (:func:`secret_status`).
    """
    out = cfg.model_dump(mode="json", by_alias=True, exclude_none=True)
    if cfg.source.kind != SourceKind.LOCAL:
        out["source"].pop("path", None)
    return out


def secret_status(cfg: Config) -> list[tuple[str, str, bool]]:
    """Every ``*_env`` key of the configuration and whether its variable is set.

    Parameters
    ----------
    cfg : Config
        The configuration.

    Returns
    -------
    list of (str, str, bool)
        (KEY, VARIABLE, set).
    """
    lines = []

    def walk(doc: Any, where: str) -> None:
        if isinstance(doc, dict):
            for k, v in doc.items():
                if k.endswith("_env") and v:
                    lines.append((f"{where}{k}", v, bool(env_secret(v))))
                walk(v, f"{where}{k}.")
        elif isinstance(doc, list):
            for i, v in enumerate(doc):
                walk(v, f"{where[:-1]}[{i}].")

    walk(effective(cfg), "")
    return lines


def json_schema() -> str:
    """The JSON Schema of the file (``docs/crisgeo-config.schema.json``; editors validate YAML with it).

    Returns
    -------
    str
        The schema, JSON.
    """
    schema = Config.model_json_schema(by_alias=True, mode="validation")
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "crisgeo-monitor configuration"
    return json.dumps(schema, indent=2, sort_keys=True) + "\n"


# -- the file


MAX_CONFIG_BYTES = 1 << 20


class _Loader(yaml.SafeLoader):
    """Safe YAML without anchors and aliases: a configuration needs none, and aliases nest into bombs."""

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.events.AliasEvent):
            mark = self.peek_event().start_mark
            raise ConfigError(
                f"line {mark.line + 1}: YAML aliases (*name) are not allowed in the configuration"
            )
        event = self.peek_event()
        if getattr(event, "anchor", None):
            raise ConfigError(
                f"line {event.start_mark.line + 1}: YAML anchors (&name) are not allowed in the configuration"
            )
        return super().compose_node(parent, index)

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if isinstance(key, (list, dict)):
                raise ConfigError(f"line {key_node.start_mark.line + 1}: a mapping key must be a scalar")
            if key in seen:
                raise ConfigError(
                    f"line {key_node.start_mark.line + 1}: key {str(key)[:60]!r} is given twice in one "
                    "mapping"
                )
            seen.add(key)
        return super().construct_mapping(node, deep)


def read_yaml(path: Path) -> Any:
    """The YAML document in a file: at most 1 MiB, safe types only, no anchors or aliases.

    Parameters
    ----------
    path : Path
        The file.

    Returns
    -------
    object
        The document.
    """
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read ({exc.strerror})") from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise ConfigError(f"{path}: larger than {MAX_CONFIG_BYTES >> 20} MiB")
    try:
        return yaml.load(raw.decode("utf-8"), Loader=_Loader)  # noqa: S506 - _Loader is a SafeLoader
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: not UTF-8 text") from None
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: {yaml_problem(exc)}") from None


def yaml_problem(exc: yaml.YAMLError) -> str:
    """A YAML error as one line: where (line, column) and what.

    Parameters
    ----------
    exc : yaml.YAMLError
        The error.

    Returns
    -------
    str
        The line.
    """
    mark = getattr(exc, "problem_mark", None)
    problem = " ".join(str(getattr(exc, "problem", None) or exc).split())[:200]
    where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
    return f"not valid YAML: {where}{problem}"
