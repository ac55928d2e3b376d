"""Hostile granules: deterministic mutants of simulated files of all four products.

Every mutant either reads (its values then pass the product table's checks) or raises the project's own
``GranuleError``; no other exception escapes the readers. A sample of mutants is assessed next to the
intact files: the result either names the mutant in its skipped list, or equals the intact result on
every unflagged FOR (1 urad).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from monitor.assess import AssessConfig, assess_paths
from monitor.sdr import GranuleError, read_file
from monitor.sdr.products import PRODUCTS
from monitor.sdr.readers import read_metadata

PER_PRODUCT = {"GCRSO": 350, "SCRIF": 350, "SVI05": 150, "GITCO": 150}  # 1000 mutants (-m slow)
# the default suite: fewer mutants of the large VIIRS files (copying them is most of the time), still
# every family of mutation on every product
QUICK = {"GCRSO": 350, "SCRIF": 350, "SVI05": 40, "GITCO": 40}
FAMILIES = ("dtype", "shape", "value", "attribute", "structure", "bytes", "factors", "time")
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


def mutate(path: Path, prefix: str, family: str, rng) -> str:
    """Apply one mutation of *family* to the file at *path*; return what was done."""
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


@pytest.mark.parametrize("per_product", [QUICK, pytest.param(PER_PRODUCT, marks=pytest.mark.slow)])
def test_no_mutant_escapes_the_readers(cases, scratch, per_product):
    base, _, _ = cases.get()
    outcomes = {"read": 0, "rejected": 0}
    mutants = _mutants(per_product)
    for prefix, k, family in mutants:
        src = sorted(base.glob(f"{prefix}_*.h5"))[0]
        dst = scratch / src.name
        shutil.copyfile(src, dst)
        what = mutate(dst, prefix, family, np.random.default_rng(1000 * k + len(prefix)))
        try:
            read_metadata(dst)
            read_file(dst)
            outcomes["read"] += 1
        except GranuleError as exc:
            assert dst.name in str(exc), what
            outcomes["rejected"] += 1
        except Exception as exc:  # noqa: BLE001 - the point of the test
            pytest.fail(f"{prefix} mutant {k} ({family}: {what}) raised {type(exc).__name__}: {exc}")
        finally:
            dst.unlink()
    assert sum(outcomes.values()) == len(mutants) and outcomes["rejected"] > len(mutants) / 2, outcomes


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
    what = mutate(work / victim.name, prefix, family, np.random.default_rng(1000 * k + len(prefix)))
    try:
        result = assess_paths([work], AssessConfig(bootstrap=30))
    except (GranuleError, ValueError) as exc:
        assert victim.name in str(exc), what
        return
    if any(victim.name in s["item"] + s["reason"] for s in result.skipped):
        return
    for a, b in zip(result.fors, intact.fors, strict=True):
        if a.reliable and b.reliable:
            assert abs(a.d_alpha_urad - b.d_alpha_urad) <= 1 and abs(a.d_beta_urad - b.d_beta_urad) <= 1, what
