"""Render time of the HTML report for years of daily runs, and a screenshot of a report page.

    .venv/bin/python benchmarks/report_render.py [--years 3] [--satellites npp j01 j02]
    .venv/bin/python benchmarks/report_render.py --screenshot demo-state/report/j01/index.html
    docs/report-demo.png

The first form fills a temporary store with synthetic daily results (monitor.simulate.history) and
prints the time to build the report; the bound is one minute for 3 years x 3 satellites.
The second opens a page in headless Chromium (Debian chromium + chromium-driver) and saves a PNG.
"""

from __future__ import annotations

import argparse
import datetime as dt
import shutil
import sys
import tempfile
import time
from pathlib import Path

from monitor.service.outputs.report.html import ReportOptions, build_report
from monitor.service.store.sqlite import Store
from monitor.simulate.history import fill_store


def screenshot(page: Path, out: Path, width: int = 1200) -> None:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", f"--window-size={width},1000"):
        options.add_argument(arg)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)
    try:
        driver.get(page.resolve().as_uri())
        height = driver.execute_script("return document.body.scrollHeight")
        driver.set_window_size(width, height + 40)
        out.parent.mkdir(parents=True, exist_ok=True)
        driver.save_screenshot(str(out))
    finally:
        driver.quit()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--years", type=int, default=3)
    p.add_argument("--satellites", nargs="+", default=["npp", "j01", "j02"])
    p.add_argument("--screenshot", nargs=2, metavar=("PAGE", "OUT_PNG"))
    args = p.parse_args()
    if args.screenshot:
        screenshot(Path(args.screenshot[0]), Path(args.screenshot[1]))
        print(f"wrote {args.screenshot[1]}")
        return 0
    work = Path(tempfile.mkdtemp(prefix="crisgeo-report-"))
    try:
        store = Store(work / "s.sqlite")
        days = 365 * args.years
        t0 = time.perf_counter()
        fill_store(store, args.satellites, dt.date(2023, 1, 1), days, step_day=days * 2 // 3)
        fill_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        build_report(store, work / "report", ReportOptions(satellites=args.satellites))
        render_s = time.perf_counter() - t0
        store.close()
        print(
            f"{args.years} years x {len(args.satellites)} satellites ({days * len(args.satellites) * 30} "
            "per-FOR rows): "
            f"store filled in {fill_s:.1f} s, report rendered in {render_s:.1f} s (bound 60 s)"
        )
        return 0 if render_s < 60 else 1
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
