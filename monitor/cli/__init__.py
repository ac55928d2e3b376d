"""The ``crisgeo`` command line.

The daily job and the service come first (run, daemon, status, check-config, alerts, events, report,
export, reprocess, install-files), the science tools after (assess, map, simulate, fingerprint, geolocate,
regeolocate, optimize, bench).

Exit status: 0 success; 1 failure (a run failed, the store is unusable, the disk is full); 2 bad input (one
line on stderr: arguments, configuration, data); 75 another instance holds the state directory (try again
later); 130 interrupted (SIGINT), 143 terminated (SIGTERM). ``crisgeo status`` follows the Nagios plugin
convention instead: 0 OK, 1 WARNING (a warning alert fires, a threshold is passed, no success for days), 2
CRITICAL (a critical alert fires or the last run of a satellite failed), 3 UNKNOWN (a usage error, no usable
configuration or store, the timeout).
The configuration is ``--config``, else ``$CRISGEO_CONFIG``, else ``/etc/crisgeo/monitor.yaml`` (``assess``
reads one only when given).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

# the command groups register their commands (monitor.cli.registry) when imported
from monitor.cli import alerting, mapping, operations, review, science  # noqa: F401
from monitor.cli.manual import PrintReference
from monitor.cli.output import PipedOutput
from monitor.cli.registry import (
    COMMANDS,
    EXIT_ALREADY_RUNNING,
    EXIT_BAD_INPUT,
    EXIT_FAIL,
    EXIT_UNKNOWN,
    BadInput,
    Parser,
    UsageError,
)
from monitor.core.errors import DataError
from monitor.service import allocator, logs
from monitor.version import __version__

# the order of ``crisgeo --help`` and docs/cli.md
ORDER = (
    "run", "daemon", "status", "check-config", "alerts", "events", "report", "export", "reprocess",
    "install-files",
    "assess", "map", "simulate", "fingerprint", "geolocate", "regeolocate", "optimize", "bench",
)  # fmt: skip


def build_parser() -> argparse.ArgumentParser:
    """The argument parser: the global options and one subparser per entry of :data:`COMMANDS`.

    Returns
    -------
    argparse.ArgumentParser
        The parser, its commands in :data:`ORDER`.
    """
    p = Parser(
        prog="crisgeo",
        description=__doc__.replace("``", ""),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    p.add_argument("--version", action="version", version=f"crisgeo {__version__}")
    p.add_argument(
        "--cli-reference",
        action=PrintReference,
        help="print the reference of every command and option (Markdown: docs/cli.md) and exit",
    )
    p.add_argument(
        "--log-format",
        choices=("text", "json"),
        default="text",
        help="text (no timestamp under systemd: the journal adds one) or JSON lines",
    )
    common = Parser(add_help=False)  # -v and --log-format after the subcommand too
    common.add_argument(
        "-v", "--verbose", action="store_true", default=argparse.SUPPRESS, help="debug logging"
    )
    common.add_argument(
        "--log-format", choices=("text", "json"), default=argparse.SUPPRESS, help="text or JSON lines"
    )
    sub = p.add_subparsers(dest="command", required=True)
    for name in sorted(COMMANDS, key=ORDER.index):  # a command missing from ORDER fails here
        handler, help_text, arguments = COMMANDS[name]
        # the subcommand's own --help opens with what it does
        description = help_text[0].upper() + help_text[1:] + "."
        sp = sub.add_parser(name, help=help_text, description=description, parents=[common])
        for names, options in arguments:
            sp.add_argument(*names, **options)
        sp.set_defaults(func=handler)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """The crisgeo command: parse, set up logging, run the subcommand.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        The exit status: every error a command lets through is mapped here, in one line: bad input (2),
        another instance (75), an unusable store or the machine's (1), an interruption (130).
    """
    from monitor.service.lock import AlreadyRunning
    from monitor.service.store.database import StoreError

    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except UsageError as exc:
        words = sys.argv[1:] if argv is None else list(argv)
        if next((w for w in words if w in COMMANDS), None) == "status":  # a Nagios plugin: one line, stdout
            print(f"UNKNOWN - {exc}")
            return EXIT_UNKNOWN
        print(exc.usage + str(exc), file=sys.stderr)
        return EXIT_BAD_INPUT
    logs.setup(args.verbose, args.log_format)
    allocator.reuse_freed_memory()
    stdout = sys.__stdout__
    if stdout is not None and sys.stdout is stdout:
        sys.stdout = PipedOutput(stdout)
    try:
        code = args.func(args)
        sys.stdout.flush()
        return code
    except (BadInput, DataError) as exc:  # the input's fault, named in one line
        print(f"crisgeo {args.command}: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except AlreadyRunning as exc:
        print(f"crisgeo {args.command}: {exc}", file=sys.stderr)
        return EXIT_ALREADY_RUNNING
    except StoreError as exc:
        print(f"crisgeo {args.command}: {exc}", file=sys.stderr)
        return EXIT_FAIL
    except OSError as exc:  # the machine's, not the input's (a full disk, a lost mount): one line naming it
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"crisgeo {args.command}: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_FAIL
    except KeyboardInterrupt:
        return 130
