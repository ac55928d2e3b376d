"""Soak: one ``crisgeo daemon`` process works through months of simulated days while its world fails.

The daemon starts with a catch-up window of ``--days`` days and reads them from NODD as it would in
production, here an S3 server on loopback that simulates each satellite-day when it is first listed (and
keeps only the last three on disk). While the days go by, the harness breaks what the service depends on,
by the day the daemon is working on:

* the time-series database (VictoriaMetrics, real) is down for a week of days, then back;
* SMTP (aiosmtpd) answers 451 and the Slack webhook 500 for two weeks of days;
* in the middle of those, the archive answers 503 to the CrIS requests of one day: its run fails, the
  failure alert waits for SMTP and Slack, and the next daily run redoes the day.

The daily run time is set after the expected end of the catch-up, so that the daemon's own schedule redoes
the failed day. Every ``--every`` seconds the harness samples the daemon's RSS, open files and threads
(/proc) and the store's size. At the end it checks: every day recorded ok exactly once in the results;
every outbox point in VictoriaMetrics exactly once (each series holds one sample per ok day); every alert
delivery sent exactly once (the messages the SMTP and Slack servers accepted equal the deliveries the store
marks sent, and none is left pending or failed). It prints the samples and the verdicts, and exits 1 if a
check fails.

    .venv/bin/python benchmarks/soak.py [--days 90] [--seconds-per-day 20] [--keep DIR]

Needs the Debian package victoria-metrics (as the tests do). It runs about ``days x seconds-per-day``.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from contextlib import ExitStack
from http.server import BaseHTTPRequestHandler
from pathlib import Path

from aiosmtpd.controller import Controller
from aiosmtpd.smtp import Envelope

from benchmarks.servers import S3Server, Webhook, free_port, victoria_metrics, vm_export
from monitor.core.vocabulary import DeliveryStatus, RunStatus
from monitor.sdr.products import PRODUCTS
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store

ROOT = Path(__file__).resolve().parent.parent
BUCKET = "noaa-nesdis-n20-pds"
FOLDER = {p: PRODUCTS[p].collection for p in ("GCRSO", "SCRIF", "SVI05", "GITCO")}  # NODD folders
DAY_IN_PREFIX = re.compile(r"/(\d{4})/(\d{2})/(\d{2})/")


class SimulatingS3(S3Server):
    """An S3 server whose bucket fills itself: listing a day simulates it (one CrIS granule) and drops
    days older than three; requests for the CrIS files of a day in ``failing`` answer 503 (that day's run
    fails; its neighbours, which list its VIIRS granules, do not)."""

    def __init__(self, root: Path, granules: int):
        super().__init__(root, page_size=1000)
        self.granules = granules
        self.failing: set = set()
        self.lock = threading.Lock()
        self.made: list = []

    def _list(self, h: BaseHTTPRequestHandler, bucket: str, q: dict[str, list[str]]) -> None:
        prefix = q.get("prefix", [""])[0]
        if self._fails(prefix):
            return self._unavailable(h)
        m = DAY_IN_PREFIX.search("/" + prefix)
        if m:
            self._simulate(dt.date(int(m[1]), int(m[2]), int(m[3])))
        return super()._list(h, bucket, q)

    def _get(self, h: BaseHTTPRequestHandler, bucket: str, key: str) -> None:
        if self._fails(key):
            return self._unavailable(h)
        return super()._get(h, bucket, key)

    def _fails(self, key: str) -> bool:
        m = DAY_IN_PREFIX.search("/" + key)
        cris = key.startswith((FOLDER["GCRSO"] + "/", FOLDER["SCRIF"] + "/"))
        return m is not None and cris and dt.date(int(m[1]), int(m[2]), int(m[3])) in self.failing

    @staticmethod
    def _unavailable(h: BaseHTTPRequestHandler) -> None:
        h.send_response(503)
        h.send_header("Content-Length", "0")
        h.end_headers()

    def _simulate(self, day: dt.date) -> None:
        from monitor.simulate.case import simulate_case

        with self.lock:
            cris = self.root / BUCKET / FOLDER["GCRSO"] / f"{day:%Y/%m/%d}"
            if cris.is_dir() and any(cris.iterdir()):
                return  # on disk (a day dropped from the three kept is simulated again: NODD keeps all)
            work = self.root / "work" / day.isoformat()
            start = dt.datetime(day.year, day.month, day.day, 12, 0, tzinfo=dt.timezone.utc)
            simulate_case(
                work,
                satellite="j01",
                granules=self.granules,
                profile="paper",
                seed=day.toordinal() % 97,
                start=start,
            )
            for f in work.glob("*.h5"):
                product = f.name.split("_")[0]
                when = dt.datetime.strptime(f.name.split("_d")[1][:8], "%Y%m%d").date()
                d = self.root / BUCKET / FOLDER[product] / f"{when:%Y/%m/%d}"
                d.mkdir(parents=True, exist_ok=True)
                os.replace(f, d / f.name)
            shutil.rmtree(work)
            self.made = [d for d in self.made if d != day] + [day]
            for old in self.made[:-3]:  # the bucket holds three days: the disk stays bounded
                for folder in FOLDER.values():
                    shutil.rmtree(self.root / BUCKET / folder / f"{old:%Y/%m/%d}", ignore_errors=True)


class Smtp:
    """An SMTP server that accepts (and counts) messages, or answers 451 while ``failing``."""

    def __init__(self) -> None:
        self.messages: list[bytes | str | None] = []
        self.refused = 0
        self.failing = False
        self.port = free_port()
        self.controller = Controller(self, hostname="127.0.0.1", port=self.port)

    async def handle_DATA(self, server: object, session: object, envelope: Envelope) -> str:
        if self.failing:
            self.refused += 1
            return "451 4.3.0 try again later"
        self.messages.append(envelope.content)
        return "250 accepted"


def proc_sample(pid: int) -> dict | None:
    """RSS (MB), open files and threads of process *pid*; None once it has ended."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    rss = re.search(r"VmRSS:\s+(\d+)", status)
    if rss is None:  # exiting
        return None
    rss_kb = int(rss[1])
    return {
        "rss_mb": rss_kb / 1024,
        "open_files": len(os.listdir(f"/proc/{pid}/fd")),
        "threads": int(threads[1]) if (threads := re.search(r"Threads:\s+(\d+)", status)) else 0,
    }


def windows(samples: list, days: int, width: int = 10) -> list[dict]:
    """Per window of *width* finished runs: RSS (MB) at its lowest, median and highest, and the most open
    files and threads. A sample's RSS depends on where in a run it falls (a run's arrays come and go, the
    allocator hands freed memory back after each run), so the lowest of a window is the resting level."""
    import statistics

    out = []
    for lo in range(0, days + 1, width):
        w = [s for s in samples if lo <= s["runs"] < lo + width]
        if w:
            rss = [s["rss_mb"] for s in w]
            out.append(
                {
                    "runs": f"{lo}-{lo + width - 1}",
                    "rss_min": min(rss),
                    "rss_median": statistics.median(rss),
                    "rss_max": max(rss),
                    "open_files": max(s["open_files"] for s in w),
                    "threads": max(s["threads"] for s in w),
                    "store_mb": max(s["store_mb"] for s in w),
                }
            )
    return out


def memory_verdict(samples: list, days: int) -> list[str]:
    """Print the windows; the failures: resting RSS (window minimum) of the last window more than 10 %
    above that of runs 10-19, or more open files or threads."""
    rows = windows(samples, days)
    print("runs     rss_min  rss_median  rss_max  open_files  threads  store_mb")
    for r in rows:
        print(
            f"{r['runs']:<8} {r['rss_min']:7.0f} {r['rss_median']:11.0f} {r['rss_max']:8.0f} "
            f"{r['open_files']:11d} {r['threads']:8d} {r['store_mb']:9.2f}"
        )
    first = next((r for r in rows if r["runs"].startswith("10-")), None)
    last = rows[-1] if rows else None
    if first is None or last is None or last is first:
        return ["too few samples for the memory verdict"]
    failures = []
    growth = last["rss_min"] / first["rss_min"] - 1
    print(
        f"soak: resting RSS runs 10-19 {first['rss_min']:.0f} MB, runs {last['runs']} "
        f"{last['rss_min']:.0f} MB ({100 * growth:+.1f} %); "
        f"open files {first['open_files']} -> {last['open_files']}; "
        f"threads {first['threads']} -> {last['threads']}"
    )
    if growth > 0.10:
        failures.append(f"resting RSS grew {100 * growth:.1f} % from runs 10-19 to {last['runs']}")
    if last["open_files"] > first["open_files"] or last["threads"] > first["threads"]:
        failures.append("open files or threads grew")
    return failures


def write_config(
    work: Path, s3_url: str, vm_url: str, smtp_port: int, days: int, run_at: dt.datetime
) -> Path:
    events = work / "events.yaml"
    events.write_text((ROOT / "configs" / "events.yaml").read_text())
    path = work / "soak.yaml"
    path.write_text(
        f"""satellites: [j01]
state_dir: {work / "state"}
source:
  kind: nodd
  endpoint: "{s3_url}/{{bucket}}"
  timeout_s: 120
  retries: 2
  backoff_s: 1
  cache_max_mb: 1000
schedule:
  time_utc: "{run_at:%H:%M}"
  catch_up_days: {days}
  lag_days: 1
scenes: {{candidates: 4, keep: 4}}
fingerprint: {{granules: 2}}
store:
  publish: [{{kind: influx1, url: "{vm_url}"}}]
  drain_minutes: 0.5
report_dir: {work / "state" / "report"}
http: {{listen: "127.0.0.1:0"}}
alerts:
  log: {work / "state" / "alerts.log"}
  events_file: {events}
  email: {{host: 127.0.0.1, port: {smtp_port}, starttls: false, to: [team@example.org]}}
  slack: {{webhook_env: SOAK_SLACK}}
"""
    )
    return path


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--days", type=int, default=90)
    ap.add_argument("--granules", type=int, default=1, help="CrIS granules simulated per day")
    ap.add_argument("--seconds-per-day", type=float, default=20.0, help="expected wall time of one day")
    ap.add_argument("--every", type=float, default=5.0, help="seconds between samples")
    ap.add_argument("--keep", type=Path, help="work directory to keep (default: a temporary one)")
    args = ap.parse_args(argv)
    work = args.keep or Path(tempfile.mkdtemp(prefix="crisgeo-soak-"))
    work.mkdir(parents=True, exist_ok=True)
    today = dt.datetime.now(dt.timezone.utc).date()
    first = today - dt.timedelta(days=args.days)
    days = [first + dt.timedelta(days=k) for k in range(args.days)]
    at = [days[int(f * args.days)] for f in (0.2, 0.28, 0.4, 0.5, 0.6)]  # of 90: days 18, 25, 36, 45, 54
    vm_down, vm_up = at[0], at[1]  # a week without the time-series database
    mail_down, mail_up = at[2], at[4]  # SMTP and Slack fail for days, while...
    s3 = SimulatingS3(work / "s3", args.granules)
    s3.failing = {at[3]}  # ...the archive answers 503 for one day: its failure alert waits for them
    smtp, slack = Smtp(), Webhook()
    run_at = dt.datetime.now(dt.timezone.utc) + dt.timedelta(
        seconds=args.days * args.seconds_per_day * 1.4 + 180
    )
    samples, store_mb = [], {}
    vm_port, vm_data = free_port(), work / "vm"
    with ExitStack() as stack:
        stack.enter_context(s3)
        smtp.controller.start()
        stack.callback(smtp.controller.stop)
        vm = ExitStack()
        vm_url = vm.enter_context(victoria_metrics(vm_data, vm_port))
        give_up = run_at + dt.timedelta(hours=1)
        config = write_config(work, s3.url, vm_url, smtp.port, args.days, run_at)
        env = {**os.environ, "SOAK_SLACK": slack.url, "PYTHONPATH": str(ROOT)}
        log = open(work / "daemon.log", "w")
        daemon = subprocess.Popen(
            [sys.executable, "-m", "monitor.cli", "daemon", "--config", str(config)],
            stdout=log,
            stderr=subprocess.STDOUT,
            env=env,
            cwd=ROOT,
        )
        print(f"soak: {args.days} days {first}..{days[-1]}, daemon pid {daemon.pid}, work {work}")
        print(f"soak: the daily run (redoing the failed day) is at {run_at:%H:%M} UTC")
        t0 = time.monotonic()
        state = work / "state" / "crisgeo.sqlite"
        phase = "running"
        try:
            while daemon.poll() is None:
                time.sleep(args.every)
                if not state.exists():
                    continue
                with Store(state) as store:
                    runs = store.runs("j01")
                    outbox = store.outbox_size()
                    pending = len(AlertState(store).deliveries(DeliveryStatus.PENDING))
                finished = [r for r in runs if r.finished]
                current = dt.date.fromisoformat(runs[-1].day) if runs else first
                ok_days = {r.day for r in runs if r.status == RunStatus.OK}
                sample = proc_sample(daemon.pid)
                if sample is None:
                    break
                s = sample
                s.update(t_s=round(time.monotonic() - t0), runs=len(finished), ok_days=len(ok_days))
                s["store_mb"] = state.stat().st_size / 1e6
                samples.append(s)
                store_mb[len(finished)] = s["store_mb"]
                if current >= vm_down and current < vm_up and phase == "running":
                    vm.close()
                    phase = "vm down"
                    print(f"soak: {current}: VictoriaMetrics stopped")
                elif current >= vm_up and phase == "vm down":
                    vm = ExitStack()
                    vm.enter_context(victoria_metrics(vm_data, vm_port))
                    phase = "running"
                    print(f"soak: {current}: VictoriaMetrics back")
                # during the catch-up only: the daily run redoing the failed day (inside the window) finds
                # them back, and sends the alerts that waited
                smtp.failing = slack.failing = mail_down <= current < mail_up and len(finished) < args.days
                if current > at[3] and s3.failing:
                    s3.failing = set()  # the archive is back the next day
                    print(f"soak: {current}: the archive answers again")
                if len(samples) % 12 == 0:
                    print(
                        f"soak: t={s['t_s']} s day {current} runs {s['runs']} ok {s['ok_days']} "
                        f"rss {s['rss_mb']:.0f} MB fds {s['open_files']} threads {s['threads']} "
                        f"store {s['store_mb']:.1f} MB outbox {outbox} "
                        f"alerts pending {pending}"
                    )
                done = len(ok_days) == args.days and outbox == 0 and pending == 0
                if done and not any(r.finished is None for r in runs):
                    break
                if dt.datetime.now(dt.timezone.utc) > give_up:
                    print("soak: giving up an hour after the daily run")
                    break
        finally:
            daemon.send_signal(signal.SIGTERM)
            daemon.wait(timeout=120)
            log.close()
        # the checks
        failures = []
        with Store(state) as store:
            runs = store.runs("j01")
            deliveries = AlertState(store).deliveries()
        ok = [r for r in runs if r.status == RunStatus.OK]
        per_day: dict[str, int] = {}
        for r in ok:
            per_day[r.day] = per_day.get(r.day, 0) + 1
        if sorted(per_day) != [d.isoformat() for d in days]:
            failures.append(f"days recorded ok: {len(per_day)} of {args.days}")
        if any(n != 1 for n in per_day.values()):
            failures.append(f"days recorded ok more than once: {[d for d, n in per_day.items() if n != 1]}")
        failed = [r for r in runs if r.status == RunStatus.FAILED]
        if phase != "running":
            vm = ExitStack()
            vm.enter_context(victoria_metrics(vm_data, vm_port))
        stored = vm_export(vm_url, "cris_geolocation_total_km")
        counts = [len(x["timestamps"]) for x in stored]
        unique = [len(set(x["timestamps"])) for x in stored]
        if len(stored) != 30 or any(c != args.days for c in counts) or counts != unique:
            failures.append(
                f"VictoriaMetrics: {len(stored)} series with {sorted(set(counts))} samples "
                f"({sorted(set(unique))} distinct)"
            )
        sent = [d for d in deliveries if d.status == "sent"]
        by_channel = {c: sum(1 for d in sent if d.channel == c) for c in ("email", "slack")}
        left = [d for d in deliveries if d.status != "sent" and d.channel in ("email", "slack")]
        if by_channel["email"] != len(smtp.messages) or by_channel["slack"] != len(slack.received) or left:
            failures.append(
                f"alerts: sent email {by_channel['email']} / received {len(smtp.messages)}, "
                f"slack {by_channel['slack']} "
                f"/ received {len(slack.received)}, not sent {len(left)}"
            )
        vm.close()
    # the report
    print(
        f"\nsoak: {args.days} days in {samples[-1]['t_s'] if samples else 0} s; "
        f"{len(failed)} failed run(s) redone"
    )
    print(
        f"soak: alerts sent by email {len(smtp.messages)} (refused while down {smtp.refused}), "
        f"Slack {len(slack.received)} (refused {slack.refused})"
    )
    failures += memory_verdict(samples, args.days)
    (work / "samples.json").write_text(json.dumps(samples))
    for f in failures:
        print("soak: FAIL:", f)
    print("soak: PASS" if not failures else "soak: FAILED")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
