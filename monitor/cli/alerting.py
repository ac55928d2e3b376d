"""The alerts and the known changes: list, silence, unsilence, evaluate; the events calendar and what each
change did."""

from __future__ import annotations

import argparse
import datetime as dt
from typing import TYPE_CHECKING

from monitor.cli.registry import CONFIG, EXIT_FAIL, EXIT_OK, BadInput, arg, command, load, open_store
from monitor.cli.types import iso_time, satellite_name, until
from monitor.core.vocabulary import Rule

if TYPE_CHECKING:  # the commands import what they run when they run it: crisgeo starts fast
    from monitor.config.model import Config

RULES = tuple(r.value for r in Rule)  # as strings: argparse prints its choices' repr


@command(
    "alerts",
    "the alerts: list them, silence or unsilence a rule, evaluate the rules now, send a test notification",
    arg(
        "action",
        choices=("list", "silence", "unsilence", "evaluate", "test"),
        nargs="?",
        default="list",
        help="list (default): firing, silenced and recently resolved alerts and the silences in force; "
        "silence: quiet --rule/--satellite until --expires, with --reason; unsilence: end silence --id; "
        "evaluate: evaluate the rules and deliver now; test: a marked test message through each configured "
        "channel (or --channel), reported per channel (exit 1 if one was not delivered)",
    ),
    CONFIG,
    arg("--rule", choices=RULES, help="silence: the rule (default: every rule)"),
    arg("--satellite", type=satellite_name, metavar="S", help="silence: the satellite (default: every one)"),
    arg("--expires", type=until, help="silence: when it ends (ISO 8601, UTC) or how long from now (12h, 7d)"),
    arg("--until", dest="expires", type=until, help=argparse.SUPPRESS),  # the earlier name, kept for scripts
    arg("--reason", default="", help="silence: why (shown with the silence)"),
    arg("--id", type=int, help="unsilence: the silence's number (crisgeo alerts list shows it)"),
    arg("--json", action="store_true", help="list: as JSON"),
    arg("--channel", choices=("email", "slack", "alertmanager"), help="test: only this channel"),
)
def cmd_alerts(args: argparse.Namespace) -> int:
    """crisgeo alerts: list, silence, unsilence, evaluate, test.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from alerts.engine import alerts_view, evaluate_and_deliver
    from monitor.service.store.alert_state import AlertState, SilenceError
    from monitor.service.store.sqlite import Store

    now = dt.datetime.now(dt.timezone.utc)
    if args.action == "test":  # reads and writes nothing of the store
        from alerts.probe import probe

        try:
            outcomes = probe(load(args).alerts, args.channel, now)
        except ValueError as exc:
            raise BadInput(str(exc)) from None
        if not outcomes:
            raise BadInput(
                "no notification channel configured (alerts.email, alerts.slack, alerts.alertmanager)"
            )
        for o in outcomes:
            print(o.text())
        return EXIT_OK if all(o.delivered for o in outcomes) else EXIT_FAIL
    if args.action == "list":
        cfg = load(args)
        with open_store(cfg) as store:
            view = alerts_view(store, now)
        if args.json:
            import json

            print(json.dumps(view.to_dict(), indent=1))
        else:
            print(view.text())
        return EXIT_OK
    cfg = load(args, writes=True)
    with Store(cfg.store.path) as store:
        if args.action == "silence":
            if args.expires is None or not args.reason:
                raise BadInput("alerts silence needs --expires and --reason")
            try:
                AlertState(store).silence(args.rule, args.satellite, args.expires, args.reason, now)
            except SilenceError as exc:
                raise BadInput(str(exc)) from None
            print(
                f"silenced rule={args.rule or '*'} satellite={args.satellite or '*'} until "
                f"{args.expires:%Y-%m-%d %H:%M} UTC"
            )
        elif args.action == "unsilence":
            if args.id is None:
                raise BadInput("alerts unsilence needs --id (crisgeo alerts list shows the silences)")
            try:
                AlertState(store).lift(args.id, now)
            except SilenceError as exc:
                raise BadInput(str(exc)) from None
            print(f"silence {args.id} lifted")
        else:
            print(evaluate_and_deliver(store, cfg.alerts, cfg.satellites, now).text())
    return EXIT_OK


@command(
    "events",
    "list the known changes, measure what each did, or add one to the events calendar",
    arg(
        "action",
        choices=("list", "effects", "add"),
        nargs="?",
        default="list",
        help="list (default): the calendar's changes and those found in the data; effects: per change, each "
        "FOR's offsets before and after with sigmas, the move in urad and km, its significance, and the "
        "move the EPs' mapping angles predict (docs/operations.md); add: a change to the calendar (its "
        "comments are kept)",
    ),
    CONFIG,
    arg(
        "--satellite",
        type=satellite_name,
        metavar="S",
        help="list, effects: only this satellite; add: the satellite",
    ),
    arg("--time", type=iso_time, help="add: when (ISO 8601, UTC)"),
    arg("--instrument", choices=("cris", "viirs", "common"), help="add: the instrument changed"),
    arg("--kind", default="change", help="add: ep_upload, lut_change, software, ..."),
    arg("--description", help="add: what changed"),
)
def cmd_events(args: argparse.Namespace) -> int:
    """crisgeo events: list the known changes, measure what each did, or add one to the calendar.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (:func:`monitor.cli.build_parser`).

    Returns
    -------
    int
        The exit status.
    """
    from monitor.history.changes import Change, add_to_calendar, listing

    cfg = load(args)
    if cfg.events_file is None:
        raise BadInput("alerts.events_file is not set in the configuration")
    if args.action == "add":
        if not (args.satellite and args.time and args.instrument and args.description):
            raise BadInput("events add needs --satellite, --time, --instrument and --description")
        try:
            add_to_calendar(
                cfg.events_file,
                Change(args.time, args.satellite, args.instrument, args.kind, args.description, "calendar"),
            )
        except OSError as exc:
            raise BadInput(f"{cfg.events_file}: {exc.strerror or exc}") from None
        except ValueError as exc:  # its message names the file
            raise BadInput(str(exc)) from None
        print(f"added to {cfg.events_file}")
        return EXIT_OK
    if args.action == "effects":
        return _effects(cfg, args.satellite)
    try:
        if not cfg.store.path.exists():  # before the first run: the calendar alone
            changes = listing(cfg.events_file, cfg.satellites, args.satellite, None)
        else:
            with open_store(cfg) as store:
                changes = listing(cfg.events_file, cfg.satellites, args.satellite, store)
    except OSError as exc:
        raise BadInput(f"{cfg.events_file}: {exc.strerror or exc}") from None
    except ValueError as exc:  # its message names the file and the entry
        raise BadInput(str(exc)) from None
    for c in changes:
        print(f"{c.satellite} {c.label()}")
    return EXIT_OK


def _effects(cfg: Config, only: str | None) -> int:
    """Print what each known change did to the stored offsets (:mod:`alerts.effects`)."""
    from alerts.effects import change_effects, effect_text
    from monitor.history.changes import all_changes

    if not cfg.store.path.exists():
        raise BadInput(f"{cfg.store.path}: no store yet: nothing assessed to measure a change on")
    with open_store(cfg) as store:
        for sat in [only] if only else cfg.satellites:
            try:
                changes = all_changes(store, sat, cfg.events_file)
            except OSError as exc:
                raise BadInput(f"{cfg.events_file}: {exc.strerror or exc}") from None
            except ValueError as exc:  # its message names the file and the entry
                raise BadInput(str(exc)) from None
            effects = change_effects(store, sat, changes, cfg.alerts)
            if not effects:
                print(f"{sat}: no known change with assessed days on both sides")
            for e in effects:
                print(f"{sat} " + "\n".join(effect_text(e)))
    return EXIT_OK
