"""The registry of crisgeo's subcommands and what they share: exit statuses, the bad-input error, the
arguments as data, the options that are configuration keys, loading the configuration and the store."""

from __future__ import annotations

import argparse
import datetime as dt
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn, TypeVar

from monitor.cli.types import satellite_name
from monitor.config.assessment import AssessmentConfig, FingerprintConfig
from monitor.config.model import Config
from monitor.core.vocabulary import Cost, Kernel

if TYPE_CHECKING:
    from monitor.geometry.ep_model import (
        EngineeringPacket,  # the commands import what they run when they run it: crisgeo starts fast
    )
    from monitor.service.store.sqlite import Store

Handler = Callable[[argparse.Namespace], int]  # a subcommand: its parsed arguments in, its exit status out


SectionT = TypeVar("SectionT", AssessmentConfig, FingerprintConfig)  # a section that commands take as options


# the defaults of the assessment keys, for the commands that take them as flags
ASSESSMENT = AssessmentConfig()  # the defaults of the options that mirror configuration keys


FINGERPRINT = FingerprintConfig()


EXIT_OK, EXIT_FAIL, EXIT_BAD_INPUT = 0, 1, 2


EXIT_ALREADY_RUNNING = 75  # sysexits EX_TEMPFAIL


EXIT_UNKNOWN = 3  # crisgeo status, a Nagios plugin: UNKNOWN (a usage error, no usable configuration or store)


DEFAULT_CONFIG = "/etc/crisgeo/monitor.yaml"


class BadInput(Exception):
    """An error in what the user gave; reported as one line, exit status 2."""


class UsageError(Exception):
    """A command line the parser refuses: the usage of the (sub)command and the message (:class:`Parser`).

    Parameters
    ----------
    usage : str
        The usage text.
    message : str
        What is wrong.
    """

    def __init__(self, usage: str, message: str) -> None:
        super().__init__(message)
        self.usage = usage


class Parser(argparse.ArgumentParser):
    """argparse's parser, but a refused command line raises :class:`UsageError` instead of exiting 2: the
    exit status is the command's convention (``status``: Nagios UNKNOWN), decided in one place, main."""

    def error(self, message: str) -> NoReturn:
        """Raise :class:`UsageError` instead of exiting: main decides the exit status.

        Parameters
        ----------
        message : str
            argparse's message.
        """
        raise UsageError(self.format_usage(), f"{self.prog}: error: {message}")


def options(model: type[SectionT], flags: str, **values: Any) -> SectionT:
    """The options of a command that are keys of a configuration section, checked by the same model as the
    file.

    Parameters
    ----------
    model : type
        The section's model.
    flags : str
        The options, named in an error.
    **values : object
        The section's keys.

    Returns
    -------
    AssessmentConfig or FingerprintConfig
        The section; a problem is bad input naming the *flags* and the key.
    """
    from monitor.config.file import section_of
    from monitor.config.keys import ConfigError

    name = next(k for k, f in Config.model_fields.items() if f.annotation is model)
    try:
        section = section_of(name, **values)
    except ConfigError as exc:
        raise BadInput(f"{flags}: {exc}") from None
    assert isinstance(section, model)
    return section


def arg(*names: str, **options: Any) -> tuple[tuple[str, ...], dict[str, Any]]:
    """One argument of a subcommand: the add_argument call, as data.

    Parameters
    ----------
    *names : str
        Its names.
    **options : object
        add_argument's keywords.

    Returns
    -------
    tuple
        (names, options).
    """
    return names, options


CONFIG = arg("--config", help=f"configuration file (default: $CRISGEO_CONFIG, then {DEFAULT_CONFIG})")
SATELLITE = arg(
    "--satellite",
    type=satellite_name,
    metavar="S",
    help="only this satellite: npp, j01, j02, or as users write them (snpp, noaa20, n20, noaa21, n21); "
    "default every configured one",
)


# the options that are keys of the assessment section (checked by its model, :func:`options`)
KERNEL = arg(
    "--kernel",
    choices=tuple(k.value for k in Kernel),
    default=ASSESSMENT.kernel.value,
    help="FOV weighting: the top-hat cone or the CrIS spatial response (assessment.kernel)",
)


COST = arg(
    "--cost",
    choices=tuple(c.value for c in Cost),
    default=ASSESSMENT.cost.value,
    help="stdev (the paper's) or regression (unmoved by a CrIS-VIIRS gain or bias) (assessment.cost)",
)


CLOUDS = arg(
    "--clouds",
    default="ground",
    metavar="LAW",
    help="cloud tops at the height their temperature implies: lapse:G (K/km, e.g. lapse:6.5) or "
    "tropical (a profile that is not linear); default ground (flat clouds, no parallax)",
)


WORKERS = arg(
    "--workers",
    type=int,
    default=ASSESSMENT.workers,
    help=f"threads of the compiled kernels (default {ASSESSMENT.workers}, assessment.workers)",
)


def unset(argument: tuple[tuple[str, ...], dict[str, Any]]) -> tuple[tuple[str, ...], dict[str, Any]]:
    """An argument without a default (None when not given), for a command whose defaults come from a
    configuration file.

    Parameters
    ----------
    argument : tuple
        The argument (:func:`arg`).

    Returns
    -------
    tuple
        The same, default None: the help keeps saying what the default is.
    """
    names, opts = argument
    return names, {**opts, "default": None}


# name -> (handler, help, arguments), in the order of ``crisgeo --help``
COMMANDS: dict[str, tuple[Handler, str, tuple]] = {}


def command(
    name: str, help: str, *arguments: tuple[tuple[str, ...], dict[str, Any]]
) -> Callable[[Handler], Handler]:
    """Register the decorated handler as a subcommand.

    Parameters
    ----------
    name : str
        The subcommand.
    help : str
        Its one line in ``crisgeo --help``.
    *arguments : tuple
        Its arguments (:func:`arg`).

    Returns
    -------
    callable
        The decorator.
    """

    def register(handler: Handler) -> Handler:
        COMMANDS[name] = (handler, help, arguments)
        return handler

    return register


def load(args: argparse.Namespace, writes: bool = False) -> Config:
    """The configuration of a command's arguments.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``--config``, else ``$CRISGEO_CONFIG``, else the default path).
    writes : bool, optional
        Make the state directory (the commands that write).

    Returns
    -------
    Config
        The configuration; a problem is bad input naming the file.
    """

    from monitor.config.file import load_config, make_state_dir
    from monitor.config.keys import ConfigError

    args.config = args.config or os.environ.get("CRISGEO_CONFIG") or DEFAULT_CONFIG
    try:
        cfg = load_config(args.config)
        if writes:
            make_state_dir(cfg)
        return cfg
    except ConfigError as exc:
        msg = str(exc)
        named = msg.startswith((str(args.config), str(Path(args.config))))  # most errors name the file
        raise BadInput(msg if named else f"{args.config}: {msg}") from None


def open_store(cfg: Config) -> Store:
    """The configured store for a command that only reads: never created.

    Parameters
    ----------
    cfg : Config
        The configuration.

    Returns
    -------
    Store
        The store; a missing one is an error.
    """
    from monitor.service.store.sqlite import Store

    return Store(cfg.store.path, create=False)


def period(since: dt.date | None, until: dt.date | None) -> None:
    """Refuse (bad input) a period that ends before it starts.

    Parameters
    ----------
    since, until : datetime.date or None
        The period's first and last day.
    """
    if since and until and since > until:
        raise BadInput(f"--since {since} is after --until {until}")


def satellites_of(cfg: Config, satellite: str | None) -> list[str]:
    """The configured satellites, or the one asked for (which must be configured).

    Parameters
    ----------
    cfg : Config
        The configuration.
    satellite : str or None
        The one asked for.

    Returns
    -------
    list of str
        The satellites.
    """
    if satellite and satellite not in cfg.satellites:
        raise BadInput(f"satellite {satellite!r} is not in the configuration ({', '.join(cfg.satellites)})")
    return [satellite] if satellite else list(cfg.satellites)


def ep_file(path: str | os.PathLike[str], satellite: str | None = None) -> EngineeringPacket:
    """An engineering packet file, read.

    Parameters
    ----------
    path : str or os.PathLike
        The EP (XML or YAML).
    satellite : str, optional
        The satellite it must be for.

    Returns
    -------
    EngineeringPacket
        The packet.
    """
    from monitor.sdr.engpkt import load_ep

    return load_ep(path, satellite)
