"""Local sources: a directory tree of granule files, and the simulator writing such a tree."""

from __future__ import annotations

import datetime as dt
import json
import logging
import os
import shutil
import time
from collections.abc import Callable, Iterable
from pathlib import Path

from monitor.archive import ListedFile, listed, on_day
from monitor.config.source import CalibrationDifference, SourceConfig
from monitor.sdr.products import CRIS_PRODUCTS

LOG = logging.getLogger(__name__)
IN_USE_S = 600.0  # a simulated day listed this recently may still be read by a run


class LocalSource:
    """Granule files anywhere below *root*; fetching returns the file itself (nothing is downloaded).

    Parameters
    ----------
    root : str or Path
        The tree's root: every ``*.h5`` below it is considered.
    """

    spent_bytes = 0
    downloaded_files = 0
    requests = 0

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.should_stop: Callable[[], bool] | None = None

    def list_day(self, satellite: str, day: dt.date, products: Iterable[str]) -> list[ListedFile]:
        """The granule files of *satellite* on *day* (and VIIRS of the days around it) whose product is in
        *products*.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        products : iterable of str
            The product prefixes wanted (GCRSO, SCRIF, SVI05, GITCO, ...).

        Returns
        -------
        list of ListedFile
            The files.
        """
        if not self.root.is_dir():
            raise FileNotFoundError(f"source.path {self.root}: no such directory")
        out = []
        for p in sorted(self.root.rglob("*.h5")):
            f = listed(p.name, p.stat().st_size, str(p))
            if (
                f is not None
                and f.parsed.platform == satellite
                and f.product in products
                and abs((f.parsed.start.date() - day).days) <= 1
            ):
                out.append(f)
        return [f for f in out if on_day(f, day) or f.product not in CRIS_PRODUCTS]

    def fetch(self, f: ListedFile) -> Path:
        """The file itself: a local tree needs no download.

        Parameters
        ----------
        f : ListedFile
            A listed file.

        Returns
        -------
        Path
            The file.
        """
        return Path(f.location)

    def start_day(self, should_stop: Callable[[], bool] | None = None) -> None:
        """Nothing to reset for a local tree; the run's *should_stop* is kept for a simulation.

        Parameters
        ----------
        should_stop : callable, optional
            The run's stop request, polled between the long steps.
        """
        self.should_stop = should_stop


class SimulatedSource(LocalSource):
    """The offline default: each satellite-day is simulated once (paper error profile) into *root*; the
    ``source.retention_days`` most recently listed days are kept, and any another run listed in the last
    :data:`IN_USE_S` (e.g. another reprocessing worker may still read it); a day this source listed itself,
    and nobody since, is done with once the next is listed: a catch-up of months would otherwise fill the
    disk.

    Parameters
    ----------
    root : str or Path
        Where the simulated days are written.
    source_cfg : SourceConfig
        The ``source`` section (granules, profile, seed, retention).
    viirs_bands : tuple of str, optional
        The VIIRS bands simulated (I5, and the daily mapping's bands when it is on).
    """

    def __init__(
        self, root: str | Path, source_cfg: SourceConfig, viirs_bands: tuple[str, ...] = ("I5",)
    ) -> None:
        super().__init__(root)
        self.cfg = source_cfg
        self.viirs_bands = viirs_bands
        self._listed: dict[Path, float] = {}  # the days this source listed, and their time then

    def list_day(self, satellite: str, day: dt.date, products: Iterable[str]) -> list[ListedFile]:
        """Simulate the satellite-day once (into ``root/<satellite>/<day>``), then list it. A stop requested
        during the simulation ends it within a granule's step; a stop or a failure (a full disk) leaves no
        half-simulated day.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        products : iterable of str
            The product prefixes wanted (GCRSO, SCRIF, SVI05, GITCO, ...).

        Returns
        -------
        list of ListedFile
            The files.
        """
        from monitor.simulate.case import simulate_case

        target = self.root / satellite / day.isoformat()
        if (target / "truth.json").exists() and self._has_bands(target):
            os.utime(target)  # listed now: in use
        else:
            shutil.rmtree(target, ignore_errors=True)  # a day simulated before a band was wanted
            LOG.info(
                "simulating %d CrIS granules of %s on %s into %s", self.cfg.granules, satellite, day, target
            )
            difference = self.cfg.calibration.get(satellite) or CalibrationDifference()
            try:
                simulate_case(
                    target,
                    satellite=satellite,
                    granules=self.cfg.granules,
                    profile=self.cfg.profile,
                    seed=self.cfg.seed + day.toordinal() % 1000,
                    start=dt.datetime(day.year, day.month, day.day, 12, 0, tzinfo=dt.timezone.utc),
                    cris_bias_k=difference.bias_k,
                    cris_gain=difference.gain,
                    cris_nonlinear_k=difference.nonlinear_k,
                    viirs_bands=self.viirs_bands,
                    should_stop=self.should_stop,
                )
            except (
                BaseException
            ):  # stopped or out of room: a day half simulated is no day (and frees the room)
                shutil.rmtree(target, ignore_errors=True)
                raise
        self.root.mkdir(parents=True, exist_ok=True)
        self._listed[target] = target.stat().st_mtime
        self._forget_old_days(keep=target)
        return LocalSource(target).list_day(satellite, day, products)

    def _has_bands(self, target: Path) -> bool:
        """Whether the simulated day in *target* holds every VIIRS band this source simulates."""
        try:
            held = json.loads((target / "truth.json").read_text()).get("viirs_bands", ["I5"])
        except (OSError, ValueError):
            return False
        return set(self.viirs_bands) <= set(held)

    def _forget_old_days(self, keep: Path) -> None:
        days = sorted(
            (d for d in self.root.glob("*/*") if d.is_dir() and d != keep), key=lambda d: d.stat().st_mtime
        )
        recent = time.time() - IN_USE_S
        for d in days[: max(0, len(days) + 1 - max(self.cfg.retention_days, 1))]:
            mine = d in self._listed and d.stat().st_mtime <= self._listed[d]  # nobody listed it since
            if mine or d.stat().st_mtime < recent:
                shutil.rmtree(d, ignore_errors=True)
