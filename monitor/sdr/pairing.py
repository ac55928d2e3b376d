"""Find granule files, pair CrIS SDR with GEO, and attach the VIIRS I5 granules that cover each CrIS granule;
the other VIIRS bands (M13, M15, M16 with their M-band GEO) paired where asked for.

Pairing is by file name (``plat_d_t_e_b``, which an SDR and its GEO share) and, for VIIRS coverage,
by time. Of several copies of a granule (reprocessed, a later creation time) the newest that reads is used.
Files that cannot be used are returned with their reason, never dropped silently.
"""

from __future__ import annotations

import datetime as dt
import os
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from monitor.core.errors import DataError
from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import GranuleMeta, GranuleRef, as_ref
from monitor.sdr.names import parse_name
from monitor.sdr.products import CRIS_GEO, CRIS_SDR, VIIRS_GEO, VIIRS_SDR, prefixes
from monitor.sdr.readers import read_file, read_metadata

COVER_MARGIN = dt.timedelta(seconds=10)
CONTIGUOUS = dt.timedelta(seconds=5)  # VIIRS granules this close in time form one continuous swath
ByPrefix = defaultdict[str, dict[str, tuple[Path, GranuleMeta]]]  # product prefix -> key -> (path, meta)


def neighbours(
    viirs_all: list[GranuleFiles], granule: GranuleFiles
) -> tuple[GranuleFiles | None, GranuleFiles | None]:
    """The VIIRS granules just before and just after *granule* in a continuous swath (None if absent).

    Parameters
    ----------
    viirs_all : list of GranuleFiles
        The run's VIIRS granules.
    granule : GranuleFiles
        One of them.

    Returns
    -------
    before, after : GranuleFiles or None
        None where absent.
    """
    before = next(
        (v for v in viirs_all if abs(v.end - granule.start) < CONTIGUOUS and v.key != granule.key), None
    )
    after = next(
        (v for v in viirs_all if abs(v.start - granule.end) < CONTIGUOUS and v.key != granule.key), None
    )
    return before, after


@dataclass
class GranuleFiles:
    """The files of one granule: SDR and GEO (the same file for combined products, on local disk or read
    in place) and their metadata."""

    key: str
    sdr: GranuleRef
    geo: GranuleRef
    sdr_meta: GranuleMeta
    geo_meta: GranuleMeta

    @property
    def start(self) -> dt.datetime:  # numpydoc ignore=RT01
        """Start of the granule (UTC, from its GEO metadata)."""
        return self.geo_meta.start

    @property
    def end(self) -> dt.datetime:  # numpydoc ignore=RT01
        """End of the granule (UTC, from its GEO metadata)."""
        return self.geo_meta.end


@dataclass
class CasePlan:
    """CrIS granules with the VIIRS granules covering each, and every file or granule left out with why."""

    satellite: str
    cris: list[GranuleFiles] = field(default_factory=list)
    viirs: dict[str, list[GranuleFiles]] = field(default_factory=dict)  # by cris key, time-ordered
    viirs_all: list[GranuleFiles] = field(default_factory=list)  # every paired VIIRS granule, time-ordered
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (path or key, reason)
    bands: dict[str, list[GranuleFiles]] = field(default_factory=dict)  # other VIIRS bands, time-ordered
    cris_all: list[GranuleFiles] = field(default_factory=list)  # every paired CrIS granule, I5 cover or not

    def cover(self, granule: GranuleFiles, band: str) -> list[GranuleFiles]:
        """The granules of a VIIRS band that cover a CrIS granule in time (the rule of :func:`assemble`).

        Parameters
        ----------
        granule : GranuleFiles
            A CrIS granule.
        band : str
            I5, or a band of :attr:`bands`.

        Returns
        -------
        list of GranuleFiles
            Time-ordered.
        """
        pool = self.viirs_all if band == "I5" else self.bands.get(band, [])
        return [
            v for v in pool if v.start <= granule.end + COVER_MARGIN and v.end >= granule.start - COVER_MARGIN
        ]


class PlanError(DataError):
    """Inputs that cannot form an assessment at all (no files, mixed satellites)."""


def find_files(paths: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """Every ``*.h5`` file under *paths* (files or directories), sorted; missing paths raise PlanError.

    Parameters
    ----------
    paths : iterable of str or os.PathLike
        Files or directories.

    Returns
    -------
    list of Path
        The JPSS granule files found.
    """
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            out.extend(sorted(q for q in p.rglob("*.h5") if q.is_file()))
        elif p.is_file():
            out.append(p)
        else:
            raise PlanError(f"{p}: no such file or directory")
    return sorted(set(out))


def plan(paths: Sequence[str | os.PathLike[str]], bands: Sequence[str] = ("I5",)) -> CasePlan:
    """Pair the granule files found under *paths* into a :class:`CasePlan`.

    Parameters
    ----------
    paths : sequence of str or os.PathLike
        Files or directories.
    bands : sequence of str, optional
        The VIIRS bands wanted besides I5 (M13, M15, M16) are paired with their GEO into ``bands``.

    Returns
    -------
    CasePlan
        The CrIS granules in time order with the VIIRS granules covering each, and the files skipped.
    """
    files = find_files(paths)
    if not files:
        raise PlanError(f"no .h5 files in {', '.join(map(str, paths))}")
    skipped: list[tuple[str, str]] = []
    copies: defaultdict[tuple[str, str], list[tuple[Path, GranuleMeta]]] = defaultdict(list)
    platforms: defaultdict[str, int] = defaultdict(int)
    for path in files:
        name = parse_name(path.name)
        if name is None:
            skipped.append((str(path), "not a JPSS product file name"))
            continue
        try:
            metas = read_metadata(path)
        except GranuleError as exc:
            skipped.append((str(path), str(exc)))
            continue
        platforms[name.platform] += 1
        for meta in metas:
            key = (
                f"{meta.platform}_{meta.granule_id}" if len(metas) > len(name.products) else name.granule_key
            )
            copies[(meta.product, key)].append((path, meta))
    if len(platforms) > 1:
        raise PlanError(
            "mixed satellites: " + ", ".join(f"{p} ({n} files)" for p, n in sorted(platforms.items()))
        )
    if not platforms:
        raise PlanError(
            "no readable JPSS granule: "
            + "; ".join(s[1] if s[0] in s[1] else f"{s[0]}: {s[1]}" for s in skipped[:3])
        )
    satellite = next(iter(platforms))
    by_prefix: ByPrefix = defaultdict(dict)
    for (product, key), found in copies.items():
        chosen = newest_readable(found, skipped)
        if chosen is not None:
            by_prefix[product][key] = chosen
    cris = _pair(by_prefix, CRIS_SDR, CRIS_GEO, skipped)
    viirs = _pair(by_prefix, VIIRS_SDR, VIIRS_GEO, skipped)
    result = assemble(satellite, cris, viirs, skipped)
    result.cris_all = sorted(cris, key=lambda g: g.start)
    for band in bands:
        if band != "I5":
            paired = _pair(by_prefix, prefixes("viirs_sdr", band), prefixes("viirs_geo", band), skipped)
            result.bands[band] = sorted(paired, key=lambda g: g.start)
    return result


def newest_readable(
    copies: list[tuple[Path, GranuleMeta]], skipped: list[tuple[str, str]]
) -> tuple[Path, GranuleMeta] | None:
    """Of the copies of one granule (reprocessed files differ in their creation time, ``_c...``), the newest
    that reads; each copy left out joins *skipped* with why. A lone copy is taken as it is (it is read in
    full later, by the assessment), so only duplicates cost a read here.

    Parameters
    ----------
    copies : list of (Path, GranuleMeta)
        The files holding the granule, with its metadata in each.
    skipped : list
        Files left out, with why.

    Returns
    -------
    (Path, GranuleMeta) or None
        The copy to use; None when no copy reads.
    """
    if len(copies) == 1:
        return copies[0]
    chosen = None
    for path, meta in sorted(copies, key=lambda c: c[0].name, reverse=True):
        if chosen is not None:
            skipped.append(
                (str(path), f"an older copy of granule {meta.granule_id}: {chosen[0].name} is used")
            )
            continue
        try:
            read_file(path)
        except GranuleError as exc:
            skipped.append((str(path), f"{exc} (an older copy of the granule is tried)"))
            continue
        chosen = (path, meta)
    return chosen


def assemble(satellite: str, cris: list, viirs: list, skipped: list) -> CasePlan:
    """The :class:`CasePlan` of paired CrIS and VIIRS granules (:class:`GranuleFiles`): each CrIS granule
    with the VIIRS granules covering it in time; one without cover joins *skipped* with the reason. The one
    place the coverage rule lives, for ``crisgeo assess`` and the daily run alike.

    Parameters
    ----------
    satellite : str
        The satellite's short name.
    cris : list of GranuleFiles
        The CrIS granules.
    viirs : list of GranuleFiles
        The VIIRS granules.
    skipped : list
        Files left out, with why.

    Returns
    -------
    CasePlan
        The plan.
    """
    viirs = sorted(viirs, key=lambda g: g.start)
    result = CasePlan(satellite, skipped=skipped, viirs_all=viirs)
    for g in sorted(cris, key=lambda g: g.start):
        cover = [v for v in viirs if v.start <= g.end + COVER_MARGIN and v.end >= g.start - COVER_MARGIN]
        if not cover:
            skipped.append((g.key, "no VIIRS I5 granule covers this CrIS granule in time"))
            continue
        result.cris.append(g)
        result.viirs[g.key] = cover
    return result


def granule_files(
    key: str, sdr: GranuleRef, geo: GranuleRef, sdr_meta: GranuleMeta | None = None
) -> GranuleFiles:
    """The :class:`GranuleFiles` of one single-granule SDR file and its GEO file, reading the metadata not
    given (*sdr_meta*, e.g. from a granule already read). :class:`GranuleError` for a file holding other
    than one granule of its product.

    Parameters
    ----------
    key : str
        The granule's key.
    sdr, geo : GranuleRef
        The SDR file and its GEO file.
    sdr_meta : GranuleMeta, optional
        The SDR's metadata when already read.

    Returns
    -------
    GranuleFiles
        The pair with its metadata.
    """
    sdr, geo = as_ref(sdr), as_ref(geo)
    metas = []
    for path, known in ((sdr, sdr_meta), (geo, None)):
        found = [known] if known is not None else read_metadata(path)
        if len(found) != 1:
            raise GranuleError(
                path, "(file)", f"holds {len(found)} granules; one granule per file is expected"
            )
        metas.append(found[0])
    problem = partners_differ(metas[0], metas[1])
    if problem:
        raise GranuleError(sdr, "N_Granule_ID", f"{problem} (its GEO file {geo.name})")
    return GranuleFiles(key, sdr, geo, metas[0], metas[1])


def partners_differ(sdr_meta: GranuleMeta, geo_meta: GranuleMeta) -> str | None:
    """Why an SDR granule and the GEO granule paired with it by name are not the same granule, or None:
    IDPS gives both the same granule ID and the same beginning and end (docs/jpss-formats.md 1.1).

    Parameters
    ----------
    sdr_meta, geo_meta : GranuleMeta
        The two files' metadata.

    Returns
    -------
    str or None
        How they differ; None when they are partners.
    """
    if sdr_meta.granule_id != geo_meta.granule_id:
        return f"granule {sdr_meta.granule_id!r}, its GEO holds {geo_meta.granule_id!r}"
    if (
        abs(sdr_meta.start_iet_us - geo_meta.start_iet_us) > 1_000_000
        or abs(sdr_meta.end_iet_us - geo_meta.end_iet_us) > 1_000_000
    ):
        return (
            f"IET {sdr_meta.start_iet_us}..{sdr_meta.end_iet_us}, its GEO "
            f"{geo_meta.start_iet_us}..{geo_meta.end_iet_us}"
        )
    return None


def _pair(
    by_prefix: ByPrefix,
    sdr_prefixes: tuple[str, ...],
    geo_prefixes: tuple[str, ...],
    skipped: list[tuple[str, str]],
) -> list[GranuleFiles]:
    """The SDR granules of *by_prefix* paired with their GEO granules; the unpaired go to *skipped*."""
    sdrs: dict[str, tuple[Path, GranuleMeta]] = {}
    for p in sdr_prefixes:
        for key, v in by_prefix.get(p, {}).items():
            sdrs.setdefault(key, v)
    geos: dict[str, tuple[Path, GranuleMeta]] = {}
    for p in geo_prefixes:
        for key, v in by_prefix.get(p, {}).items():
            geos.setdefault(key, v)
    out = []
    for key in sorted(set(sdrs) | set(geos)):
        if key not in geos:
            skipped.append((str(sdrs[key][0]), f"no matching {'/'.join(geo_prefixes)} geolocation file"))
        elif key not in sdrs:
            skipped.append((str(geos[key][0]), f"no matching {'/'.join(sdr_prefixes)} file"))
        else:
            problem = partners_differ(sdrs[key][1], geos[key][1])
            if problem:
                skipped.append((str(sdrs[key][0]), f"not the granule of its GEO file: {problem}"))
                continue
            out.append(GranuleFiles(key, sdrs[key][0], geos[key][0], sdrs[key][1], geos[key][1]))
    return out
