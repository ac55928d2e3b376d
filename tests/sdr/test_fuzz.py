"""Hostile granules: deterministic mutants of simulated files of every product read (CrIS GEO and SDR, VIIRS
I5 and I-band GEO, VIIRS M13, M15 and M-band GEO).

Every mutant either reads or raises the project's own ``GranuleError``; no other exception escapes the
readers. A mutant that reads is compared with the intact file, number by number, as the assessment would
use them (a value that became fill, or a FOV whose quality flag went bad, is data lost, not a wrong
number):

* **harmless**: every usable number is the intact one;
* **silent**: a usable number or the granule's identity differs, and nothing stopped it: the readers
  should have refused it (at most 2 % of the mutants that should be refused, ``SILENT_SHARE``);
* **undetectable**: a sparse edit of values within the field's physical range (fewer than 2 % of them, by
  the value or bit-flip families); IDPS files carry no checksums, so no relation between fields refuses
  it. Counted apart, and reported. An attitude's sign is of this kind too, and harmless to the offsets
  (tested apart).

A sample of mutants is assessed next to the intact files: the result either names the mutant in its
skipped list, or equals the intact result on every unflagged FOR (1 urad).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from monitor.assessment.assess import assess_paths
from monitor.config.assessment import AssessmentConfig
from monitor.sdr import CrisSdrGranule, GranuleError, ViirsSdrGranule, read_file
from monitor.sdr.products import PRODUCTS
from monitor.sdr.readers import read_metadata

PER_PRODUCT = {  # 2640 mutants (-m slow)
    "GCRSO": 700,
    "SCRIF": 700,
    "SVI05": 320,
    "GITCO": 320,
    "SVM15": 200,
    "SVM13": 200,
    "GMTCO": 200,
}
# the default suite: fewer mutants of the large VIIRS files (copying them is most of the time), still
# every family of mutation on every product
QUICK = {"GCRSO": 180, "SCRIF": 180, "SVI05": 27, "GITCO": 27, "SVM15": 18, "SVM13": 18, "GMTCO": 18}
M_BANDS = ("I5", "M13", "M15", "M16")  # the case the M-band products' mutants come from
FAMILIES = ("dtype", "shape", "value", "attribute", "structure", "bytes", "factors", "time", "physics")
SILENT_SHARE = 0.02
EXTREMES = (1e28, -1e28, np.inf, -np.inf, np.nan, 0.0, -307.0, 65535, -999.3, 7e9)
BAD_ATTRS = ("abc", "", -5, 0, 10**19, 1e300, "NPP", "J02")
GRAN_ATTRS = (
    "N_Number_Of_Scans",
    "N_Beginning_Time_IET",
    "N_Ending_Time_IET",
    "N_Granule_ID",
    "Beginning_Time",
    "Beginning_Date",
    "N_Beginning_Orbit_Number",
    "Ascending/Descending_Indicator",
)


def _scratch(tmp_path_factory) -> Path:
    shm = Path("/dev/shm")
    if shm.is_dir() and os.access(shm, os.W_OK):
        return Path(__import__("tempfile").mkdtemp(prefix="crisgeo-fuzz-", dir=shm))
    return tmp_path_factory.mktemp("fuzz")


def _replace(h5, name, data):
    attrs = dict(h5[name].attrs)
    del h5[name]
    d = h5.create_dataset(name, data=data)
    for k, v in attrs.items():
        d.attrs[k] = v


PHYSICS = {  # what once read silently, product by product
    "GCRSO": (
        "MidTime 0",
        "MidTime -1",
        "MidTime a day late",
        "Latitude constant",
        "Longitude constant",
        "SatelliteRange constant",
        "SCAttitude zero",
        "SCAttitude x1000",
        "SCAttitude constant",
        "N_Granule_ID empty",
        "N_Granule_ID of the next granule",
        "scans cut off",
        "relabelled S-NPP",
        "SCPosition of another time",
        "FORTime 0",
        "FORTime -1",
        "FORTime fill",
        "SCVelocity negated",
    ),
    "SCRIF": (
        "Ending_Time before the start",
        "N_Granule_ID of the next granule",
        "scans cut off",
        "relabelled S-NPP",
        "N_Beginning_Orbit_Number of S-NPP",
        "ES_RealLW negated",
        "ES_RealLW constant",
    ),
    "SVI05": (
        "N_Ending_Time_IET before the start",
        "N_Number_Of_Scans minus one",
        "BrightnessTemperature as uint8",
        "BrightnessTemperature 10 % zeros",
        "N_Beginning_Time_IET a float",
        "N_Granule_ID of the next granule",
        "relabelled S-NPP",
        "BrightnessTemperature shuffled",
        "BrightnessTemperature noise",
        "BrightnessTemperature as float",
    ),
    "GITCO": (
        "MidTime fill",
        "StartTime -1",
        "MidTime reversed",
        "SCAttitude zero",
        "SCAttitude noise",
        "SCAttitude constant",
        "N_Granule_ID of the next granule",
        "relabelled S-NPP",
        "Latitude constant",
        "SCPosition of another time",
    ),
}
PHYSICS["SVM15"] = PHYSICS["SVI05"]  # the M-band products share the I-band ones' relations
PHYSICS["GMTCO"] = PHYSICS["GITCO"]
PHYSICS["SVM13"] = tuple(p for p in PHYSICS["SVI05"] if "as uint8" not in p and "as float" not in p)


def _base(cases, prefix: str) -> Path:
    """The simulated case a product's mutants are made from."""
    return cases.get(bands=M_BANDS)[0] if prefix.startswith(("SVM", "GM")) else cases.get()[0]


def _physics(path: Path, prefix: str, h5, k: int) -> tuple[str, Path]:
    """The *k*-th mutation of :data:`PHYSICS` for *prefix* (the file stays open; renames after)."""
    product = PRODUCTS[prefix]
    group = product.data_group
    gran = h5[f"Data_Products/{product.collection}/{product.collection}_Gran_0"]
    what = PHYSICS[prefix][k % len(PHYSICS[prefix])]
    new_path = path

    def set_ds(field, fn):
        name = f"{group}/{field}"
        h5[name][...] = fn(h5[name][()])

    if what.startswith("MidTime"):
        value = {"MidTime 0": 0, "MidTime -1": -1, "MidTime fill": -993}.get(what)
        if what == "MidTime a day late":
            set_ds("MidTime", lambda t: t + 86_400_000_000)
        elif what == "MidTime reversed":
            set_ds("MidTime", lambda t: t[::-1].copy())
        else:
            set_ds("MidTime", lambda t: np.full_like(t, value))
    elif what.startswith("FORTime"):
        value = {"FORTime 0": 0, "FORTime -1": -1, "FORTime fill": -993}[what]
        set_ds("FORTime", lambda t: np.full_like(t, value))
    elif what == "SCVelocity negated":
        set_ds("SCVelocity", lambda a: -a)
    elif what == "ES_RealLW negated":
        set_ds("ES_RealLW", lambda a: -a)
    elif what == "ES_RealLW constant":
        set_ds("ES_RealLW", lambda a: np.broadcast_to(a[0, 0, 0], a.shape).copy())
    elif what == "BrightnessTemperature shuffled":
        set_ds(
            "BrightnessTemperature",
            lambda a: np.random.default_rng(k).permutation(a.ravel()).reshape(a.shape),
        )
    elif what == "BrightnessTemperature noise":

        def noise(a):
            fill = a >= 65528 if a.dtype.kind == "u" else a < -999
            lo, hi = np.percentile(a[~fill], [1, 99])
            return np.where(fill, a, np.random.default_rng(k).uniform(lo, hi, a.shape)).astype(a.dtype)

        set_ds("BrightnessTemperature", noise)
    elif what == "BrightnessTemperature as float":
        name = f"{group}/BrightnessTemperature"
        _replace(h5, name, h5[name][()].astype(np.float32))
    elif what == "StartTime -1":
        set_ds("StartTime", lambda t: np.full_like(t, -1))
    elif what.endswith("constant"):
        set_ds(what.split()[0], lambda a: np.full_like(a, a.flat[a.size // 2]))
    elif what == "SCAttitude zero":
        set_ds("SCAttitude", np.zeros_like)
    elif what == "SCAttitude x1000":
        set_ds("SCAttitude", lambda a: a * 1000)
    elif what == "SCAttitude noise":
        set_ds("SCAttitude", lambda a: np.random.default_rng(k).normal(0, 100, a.shape).astype(a.dtype))
    elif what == "SCPosition of another time":
        set_ds("SCPosition", lambda a: np.roll(a, 1, axis=0))
    elif what == "N_Granule_ID empty":
        gran.attrs["N_Granule_ID"] = np.array([[b""]])
    elif what == "N_Granule_ID of the next granule":
        gid = gran.attrs["N_Granule_ID"].ravel()[0].decode()
        gran.attrs["N_Granule_ID"] = np.array([[f"{gid[:3]}{int(gid[3:]) + 320:012d}".encode()]])
    elif what == "scans cut off":
        n = int(np.asarray(gran.attrs["N_Number_Of_Scans"]).ravel()[0])
        for f in product.fields.values():
            name = f"{group}/{f.dataset}"
            if name in h5:
                _replace(h5, name, h5[name][()][: n - 1])
        gran.attrs["N_Number_Of_Scans"] = np.array([[n - 1]], np.int32)
    elif what in ("relabelled S-NPP", "N_Beginning_Orbit_Number of S-NPP"):
        if what == "relabelled S-NPP":
            h5.attrs["Platform_Short_Name"] = np.array([[b"NPP"]])
            gid = gran.attrs["N_Granule_ID"].ravel()[0].decode()
            gran.attrs["N_Granule_ID"] = np.array([[("NPP" + gid[3:]).encode()]])
            new_path = path.with_name(path.name.replace("_j01_", "_npp_"))
        else:
            gran.attrs["N_Beginning_Orbit_Number"] = np.array([[65000]], np.uint64)
    elif what == "Ending_Time before the start":
        gran.attrs["Ending_Time"] = np.array([[b"115959.000000Z"]])
    elif what == "N_Ending_Time_IET before the start":
        start = int(np.asarray(gran.attrs["N_Beginning_Time_IET"]).ravel()[0])
        gran.attrs["N_Ending_Time_IET"] = np.array([[start - 5_000_000]], np.uint64)
    elif what == "N_Beginning_Time_IET a float":
        start = int(np.asarray(gran.attrs["N_Beginning_Time_IET"]).ravel()[0])
        gran.attrs["N_Beginning_Time_IET"] = np.array([[float(start)]])
    elif what == "N_Number_Of_Scans minus one":
        n = int(np.asarray(gran.attrs["N_Number_Of_Scans"]).ravel()[0])
        gran.attrs["N_Number_Of_Scans"] = np.array([[n - 1]], np.int32)
    elif what == "BrightnessTemperature as uint8":
        name = f"{group}/BrightnessTemperature"
        _replace(h5, name, (h5[name][()] >> 8).astype(np.uint8))
    elif what == "BrightnessTemperature 10 % zeros":

        def zeros(a):
            flat = a.reshape(-1).copy()
            flat[np.random.default_rng(k).choice(flat.size, flat.size // 10, replace=False)] = 0
            return flat.reshape(a.shape)

        set_ds("BrightnessTemperature", zeros)
    else:
        raise AssertionError(what)
    return what, new_path


def mutate(path: Path, prefix: str, family: str, rng, index: int = 0) -> tuple[str, Path]:
    """Apply one mutation of *family* to the file at *path* (for the physics family, the *index*-th);
    return what was done and where the mutant is (a relabelled granule gets its new satellite's name)."""
    if family == "physics":
        with h5py.File(path, "r+") as h5:
            what, new_path = _physics(path, prefix, h5, index)
        if new_path != path:
            path.rename(new_path)
        return what, new_path
    return _mutate(path, prefix, family, rng), path


def _mutate(path: Path, prefix: str, family: str, rng) -> str:
    product = PRODUCTS[prefix]
    group = product.data_group
    if family == "bytes":
        raw = bytearray(path.read_bytes())
        spots = rng.integers(1024, len(raw), size=int(rng.integers(1, 64)))
        for s in spots:
            raw[s] ^= 1 << int(rng.integers(0, 8))
        path.write_bytes(bytes(raw))
        return f"{len(spots)} bit flips"
    with h5py.File(path, "r+") as h5:
        names = sorted(
            f"{group}/{f.dataset}" for f in product.fields.values() if f"{group}/{f.dataset}" in h5
        )
        name = names[int(rng.integers(len(names)))]
        data = h5[name][()]
        gran = f"Data_Products/{product.collection}/{product.collection}_Gran_0"
        if family == "dtype":
            dtype = [np.float16, np.int8, np.uint8, np.int64, "S8", np.complex64][int(rng.integers(6))]
            with np.errstate(over="ignore", invalid="ignore"):  # the mutant's values may not fit: so be it
                new = data.astype(dtype) if dtype != "S8" else data.astype(str).astype("S8")
            _replace(h5, name, new)
            return f"{name} as {np.dtype(dtype)}"
        if family == "shape":
            how = int(rng.integers(4))
            if how == 0 and data.ndim >= 1:
                new = data[..., :-1] if data.shape[-1] > 1 else data[..., :0]
            elif how == 1:
                new = np.concatenate([data, data[..., -1:]], axis=-1)
            elif how == 2:
                new = data.reshape(-1)
            else:
                new = data[:-1] if len(data) > 1 else data[:0]
            _replace(h5, name, new)
            return f"{name} shape {data.shape} -> {new.shape}"
        if family == "value":
            value = EXTREMES[int(rng.integers(len(EXTREMES)))]
            flat = data.reshape(-1).copy()
            n = int(rng.choice([1, max(1, flat.size // 50), flat.size]))
            at = rng.choice(flat.size, n, replace=False)
            with np.errstate(invalid="ignore", over="ignore"):
                flat[at] = (
                    np.array(value).astype(flat.dtype)
                    if flat.dtype.kind in "iu" and not np.isfinite(value)
                    else np.array(value, dtype=np.float64).astype(flat.dtype)
                )
            h5[name][...] = flat.reshape(data.shape)
            return f"{name}: {n} value(s) set to {value}"
        if family == "attribute":
            key = GRAN_ATTRS[int(rng.integers(len(GRAN_ATTRS)))]
            value = BAD_ATTRS[int(rng.integers(len(BAD_ATTRS)))]
            if rng.random() < 0.2:
                h5.attrs["Platform_Short_Name"] = np.array([[b"NPP"]])
                return "Platform_Short_Name NPP"
            if key in h5[gran].attrs and rng.random() < 0.2:
                del h5[gran].attrs[key]
                return f"{gran}/{key} deleted"
            h5[gran].attrs[key] = np.array([[str(value).encode()]]) if isinstance(value, str) else value
            return f"{gran}/{key} = {value!r}"
        if family == "structure":
            victim = [name, group, gran, f"Data_Products/{product.collection}"][int(rng.integers(4))]
            del h5[victim]
            return f"{victim} deleted"
        if family == "factors" and any(f.factors for f in product.fields.values()):
            fac = f"{group}/BrightnessTemperatureFactors"
            value = [0.0, -0.003, np.nan, 1e30, -999.3, np.inf][int(rng.integers(6))]
            arr = h5[fac][()]
            arr[int(rng.integers(2))] = value
            h5[fac][...] = arr
            return f"{fac} = {arr.tolist()}"
        times = [n for n in names if n.endswith(("FORTime", "StartTime", "MidTime"))]
        if family == "time" and times:
            name = times[int(rng.integers(len(times)))]
            t = h5[name][()]
            how = int(rng.integers(3))
            new = (
                t - 3_600_000_000 if how == 0 else t[::-1].copy() if how == 1 else np.full_like(t, t.flat[0])
            )
            h5[name][...] = new.reshape(t.shape)
            return f"{name} {['an hour early', 'reversed', 'constant'][how]}"
        h5.attrs["Platform_Short_Name"] = np.array([[b"J02"]])
        return "Platform_Short_Name J02"


def _mutants(per_product):
    out = []
    for prefix, n in per_product.items():
        for k in range(n):
            out.append((prefix, k, FAMILIES[k % len(FAMILIES)]))
    return out


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    d = _scratch(tmp_path_factory)
    yield d
    shutil.rmtree(d, ignore_errors=True)


IDENTITY = ("platform", "granule_id", "start_iet_us", "end_iet_us", "n_scans", "orbit")


def _usable(granule) -> dict:
    """The numbers of a granule as the assessment uses them: NaN where it would not (fill, bad quality)."""
    out = {}
    for name, value in vars(granule).items():
        if isinstance(value, np.ndarray) and name not in ("qf1", "qf3", "qf1_scan"):
            out[name] = value
    if isinstance(granule, (CrisSdrGranule, ViirsSdrGranule)):
        key = "radiance_lw" if isinstance(granule, CrisSdrGranule) else "bt_k"
        good = granule.good[..., None] if key == "radiance_lw" else granule.good
        out[key] = np.where(good, out[key], np.nan)
    return out


def classify(prefix: str, family: str, intact: list, mutant: list) -> str:
    """harmless, silent or undetectable (see the module docstring) for a mutant that read."""
    if len(intact) != len(mutant):
        return "silent"
    fields = {f.dataset: (key, f) for key, f in PRODUCTS[prefix].fields.items()}
    changed, total, in_range = 0, 0, True
    for a, b in zip(intact, mutant, strict=True):
        if any(getattr(a.meta, k) != getattr(b.meta, k) for k in IDENTITY):
            return "silent"
        ua, ub = _usable(a), _usable(b)
        for key in ua:
            if key not in ub:  # an optional dataset (the CrIS SW spectra) deleted: data lost, not changed
                continue
            x, y = ua[key], ub[key]
            if x.shape != y.shape:
                return "silent"
            if x.dtype.kind == "f":
                diff = ~((x == y) | np.isnan(y))  # a value turned into fill is data lost, not a wrong number
            else:
                diff = x != y
            n = int(np.count_nonzero(diff))
            changed += n
            total += x.size
            field = next((f for k, f in fields.values() if k == key), None)
            if n and field is not None and field.limits is not None and y.dtype.kind == "f":
                lo, hi = (v * field.to_si for v in field.limits)
                in_range &= bool(np.all((y[diff] >= min(lo, hi)) & (y[diff] <= max(lo, hi))))
    if changed == 0:
        return "harmless"
    if family in ("value", "bytes") and in_range and changed < 0.02 * total:
        return "undetectable"
    return "silent"


def run_mutants(cases, scratch, per_product) -> dict:
    """Every mutant of *per_product*, read and classified: {outcome: [(prefix, k, family, what), ...]}."""
    outcomes = {"rejected": [], "harmless": [], "silent": [], "undetectable": []}
    intact = {p: read_file(sorted(_base(cases, p).glob(f"{p}_*.h5"))[0]) for p in per_product}
    for prefix, k, family in _mutants(per_product):
        src = sorted(_base(cases, prefix).glob(f"{prefix}_*.h5"))[0]
        dst = scratch / src.name
        shutil.copyfile(src, dst)
        rng = np.random.default_rng(1000 * k + len(prefix))
        what, dst = mutate(dst, prefix, family, rng, index=k // len(FAMILIES))
        try:
            read_metadata(dst)
            outcome = classify(prefix, family, intact[prefix], read_file(dst))
        except GranuleError as exc:
            assert dst.name in str(exc), what
            outcome = "rejected"
        except Exception as exc:  # noqa: BLE001 - the point of the test
            pytest.fail(f"{prefix} mutant {k} ({family}: {what}) raised {type(exc).__name__}: {exc}")
        finally:
            dst.unlink()
        outcomes[outcome].append((prefix, k, family, what))
    return outcomes


@pytest.mark.parametrize("per_product", [QUICK, pytest.param(PER_PRODUCT, marks=pytest.mark.slow)])
def test_no_mutant_escapes_the_readers_and_few_are_silent(cases, scratch, per_product):
    """No traceback; of the mutants that should be refused (rejected + silent), at most 2 % read silently.
    ``-m slow -s`` prints the counts and every silent and undetectable mutant."""
    outcomes = run_mutants(cases, scratch, per_product)
    counts = {k: len(v) for k, v in outcomes.items()}
    print(f"\n{sum(counts.values())} mutants: {counts}")
    for kind in ("silent", "undetectable"):
        for prefix, k, family, what in outcomes[kind]:
            print(f"  {kind}: {prefix} {k} {family}: {what}")
    should = counts["rejected"] + counts["silent"]
    assert sum(counts.values()) == sum(per_product.values())
    assert counts["silent"] <= SILENT_SHARE * should, outcomes["silent"]
    # every mutation that once read silently is refused
    physics = [
        m for kind in ("harmless", "silent", "undetectable") for m in outcomes[kind] if m[2] == "physics"
    ]
    assert physics == [], physics


SAMPLE = [
    ("GCRSO", 1, "shape"),
    ("GCRSO", 2, "value"),
    ("GCRSO", 7, "time"),
    ("SCRIF", 1, "shape"),
    ("SCRIF", 9, "dtype"),
    ("SVI05", 6, "factors"),
    ("GITCO", 2, "value"),
    ("GITCO", 4, "structure"),
]


@pytest.mark.parametrize("prefix,k,family", SAMPLE)
def test_assessment_names_the_mutant_or_keeps_its_numbers(cases, tmp_path, prefix, k, family):
    base, _, intact = cases.get()
    work = tmp_path / "data"
    work.mkdir()
    victim = sorted(base.glob(f"{prefix}_*.h5"))[0]
    for f in base.glob("*.h5"):
        if f != victim:
            (work / f.name).symlink_to(f)
    shutil.copyfile(victim, work / victim.name)
    what, _ = mutate(work / victim.name, prefix, family, np.random.default_rng(1000 * k + len(prefix)))
    try:
        result = assess_paths([work], AssessmentConfig())
    except (GranuleError, ValueError) as exc:
        assert victim.name in str(exc), what
        return
    if any(victim.name in s.item + s.reason for s in result.skipped):
        return
    for a, b in zip(result.fors, intact.fors, strict=True):
        if a.reliable and b.reliable:
            assert abs(a.d_alpha_urad - b.d_alpha_urad) <= 1 and abs(a.d_beta_urad - b.d_beta_urad) <= 1, what


def test_a_negated_attitude_moves_no_offset(cases, tmp_path):
    """An attitude's sign is undetectable in one granule (real roll, pitch and yaw are a few tenths of an
    arcsec either side of zero, jittering by as much from scan to scan), and harmless: the offsets are
    perturbations of the line of sight in the body frame, put back on the ground through the same rotation, so
    a sign error of a few urad in that rotation leaves them as the intact day's within 1 urad (the tolerance
    of the assessment's sample above)."""
    base, _, intact = cases.get()
    work = tmp_path / "data"
    work.mkdir()
    for f in base.glob("*.h5"):
        if f.name.startswith("GCRSO"):
            shutil.copyfile(f, work / f.name)
            with h5py.File(work / f.name, "r+") as h5:
                name = f"{PRODUCTS['GCRSO'].data_group}/SCAttitude"
                h5[name][...] = -h5[name][()]
        else:
            (work / f.name).symlink_to(f)
    result = assess_paths([work], AssessmentConfig())
    assert not result.skipped
    moved = [
        max(abs(a.d_alpha_urad - b.d_alpha_urad), abs(a.d_beta_urad - b.d_beta_urad))
        for a, b in zip(result.fors, intact.fors, strict=True)
        if a.reliable and b.reliable
    ]
    assert len(moved) >= 20 and max(moved) <= 1, max(moved)
