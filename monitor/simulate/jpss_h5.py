"""Write HDF5 files in the IDPS layout: 1024-byte XML user block, 2-D string attributes,
``/All_Data/<coll>_All`` datasets and ``/Data_Products/<coll>`` with ``_Aggr`` object references and
``_Gran_k`` region references (docs/jpss-formats.md 1.2, checked against real GCRSO files)."""

from __future__ import annotations

import datetime as dt
import os
from collections.abc import Sequence
from dataclasses import dataclass, field

import h5py
import numpy as np
from numpy.typing import DTypeLike

from monitor.core.satellites import SATELLITES
from monitor.sdr.products import Product

USERBLOCK = 1024
PLATFORM_ATTR = {s.short: s.idps for s in SATELLITES.values()}
MISSION = {s.short: s.mission for s in SATELLITES.values()}


def text_attr(value: str) -> np.ndarray:
    """An IDPS string attribute: a (1, 1) fixed-length byte array with room for a terminator.

    Parameters
    ----------
    value : str
        The text.

    Returns
    -------
    numpy.ndarray
        The attribute.
    """
    b = value.encode("ascii")
    return np.array([[b]], dtype=f"S{len(b) + 1}")


def texts_attr(values: Sequence[str]) -> np.ndarray:
    """An IDPS list-of-strings attribute: (n, 1) fixed-length bytes.

    Parameters
    ----------
    values : sequence of str
        The texts.

    Returns
    -------
    numpy.ndarray
        The attribute.
    """
    bs = [v.encode("ascii") for v in values] or [b""]
    return np.array([[b] for b in bs], dtype=f"S{max(len(b) for b in bs) + 1}")


def number_attr(value: float, dtype: DTypeLike) -> np.ndarray:
    """A numeric HDF5 attribute shaped (1, 1), as IDPS writes them.

    Parameters
    ----------
    value : float
        The number.
    dtype : numpy dtype-like
        Its type.

    Returns
    -------
    numpy.ndarray
        The attribute.
    """
    return np.array([[value]], dtype=dtype)


def _attr(value: object) -> np.ndarray:
    if isinstance(value, str):
        return text_attr(value)
    if isinstance(value, (list, tuple)) and value and isinstance(value[0], str):
        return texts_attr(value)
    return np.asarray(value)


def date_time_attrs(prefix: str, when: dt.datetime) -> dict:
    """The IDPS pair ``{prefix}_Date`` (YYYYMMDD) and ``{prefix}_Time`` (HHMMSS.ffffffZ) for *when*.

    Parameters
    ----------
    prefix : str
        ``Beginning``, ``Ending``, ...
    when : datetime.datetime
        The time, UTC.

    Returns
    -------
    dict
        The two attributes.
    """
    return {f"{prefix}_Date": when.strftime("%Y%m%d"), f"{prefix}_Time": when.strftime("%H%M%S.%fZ")}


@dataclass
class ProductData:
    """One product's arrays (granules concatenated on axis 0) and the attributes of each granule."""

    product: Product
    instrument: str
    type_tag: str
    datasets: dict
    granule_attrs: list
    granule_rows: dict  # dataset name -> rows per granule on axis 0
    fills: dict = field(default_factory=dict)
    compress: bool = True


def write_file(
    path: str | os.PathLike[str], platform: str, created: dt.datetime, products: list[ProductData]
) -> None:
    """Write *products* (one or more, for combined files) into the IDPS HDF5 file *path*.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    platform : str
        ``npp``, ``j01``, ``j02``.
    created : datetime.datetime
        The creation time, UTC.
    products : list of ProductData
        The products' data.
    """
    with h5py.File(path, "w", userblock_size=USERBLOCK) as f:
        f.attrs["Distributor"] = text_attr("noa-")
        f.attrs["Mission_Name"] = text_attr(MISSION[platform])
        f.attrs["N_Dataset_Source"] = text_attr("noa-")
        f.attrs["N_HDF_Creation_Date"] = text_attr(created.strftime("%Y%m%d"))
        f.attrs["N_HDF_Creation_Time"] = text_attr(created.strftime("%H%M%S.%fZ"))
        f.attrs["Platform_Short_Name"] = text_attr(PLATFORM_ATTR[platform])
        for pd in products:
            _write_product(f, pd)
    first = [pd.granule_attrs[0] for pd in products]
    last = [pd.granule_attrs[-1] for pd in products]
    xml = [
        "<HDF_UserBlock>",
        f"<Mission_Name>{MISSION[platform]}</Mission_Name>",
        f"<Platform_Short_Name>{PLATFORM_ATTR[platform]}</Platform_Short_Name>",
        f"<Number_of_Data_Products>{len(products)}</Number_of_Data_Products>",
    ]
    for pd, a, z in zip(products, first, last, strict=True):
        xml += [
            "<Data_Product>",
            f"<Instrument_Short_Name>{pd.instrument}</Instrument_Short_Name>",
            f"<N_Collection_Short_Name>{pd.product.collection}</N_Collection_Short_Name>",
            "<N_Processing_Domain>ops</N_Processing_Domain>",
            f"<N_Dataset_Type_Tag>{pd.type_tag}</N_Dataset_Type_Tag>",
            f"<AggregateBeginningDate>{a['Beginning_Date']}</AggregateBeginningDate>",
            f"<AggregateBeginningTime>{a['Beginning_Time']}</AggregateBeginningTime>",
            f"<AggregateEndingDate>{z['Ending_Date']}</AggregateEndingDate>",
            f"<AggregateEndingTime>{z['Ending_Time']}</AggregateEndingTime>",
            f"<AggregateBeginningGranuleID>{a['N_Granule_ID']}</AggregateBeginningGranuleID>",
            f"<AggregateEndingGranuleID>{z['N_Granule_ID']}</AggregateEndingGranuleID>",
            "</Data_Product>",
        ]
    xml.append("</HDF_UserBlock>")
    block = "".join(xml).encode("ascii")[:USERBLOCK]
    with open(path, "r+b") as fh:
        fh.write(block + b"\0" * (USERBLOCK - len(block)))


def _write_product(f: h5py.File, pd: ProductData) -> None:
    coll = pd.product.collection
    g = f.create_group(f"All_Data/{coll}_All")
    refs = []
    for name, data in pd.datasets.items():
        data = np.asarray(data)
        kw = {}
        if pd.compress and data.nbytes < 64 << 20:
            kw = {"compression": "gzip", "compression_opts": 4, "chunks": data.shape}
        fill = pd.fills.get(name, _default_fill(data.dtype))
        ds = g.create_dataset(name, data=data, fillvalue=fill, **kw)
        refs.append(ds)
    dp = f.create_group(f"Data_Products/{coll}")
    dp.attrs["Instrument_Short_Name"] = text_attr(pd.instrument)
    dp.attrs["N_Collection_Short_Name"] = text_attr(coll)
    dp.attrs["N_Dataset_Type_Tag"] = text_attr(pd.type_tag)
    dp.attrs["N_Processing_Domain"] = text_attr("ops")
    aggr = dp.create_dataset(f"{coll}_Aggr", data=np.array([d.ref for d in refs], dtype=h5py.ref_dtype))
    a0, an = pd.granule_attrs[0], pd.granule_attrs[-1]
    aggr.attrs["AggregateBeginningDate"] = text_attr(a0["Beginning_Date"])
    aggr.attrs["AggregateBeginningTime"] = text_attr(a0["Beginning_Time"])
    aggr.attrs["AggregateBeginningGranuleID"] = text_attr(a0["N_Granule_ID"])
    aggr.attrs["AggregateBeginningOrbitNumber"] = number_attr(a0["N_Beginning_Orbit_Number"], np.uint64)
    aggr.attrs["AggregateEndingDate"] = text_attr(an["Ending_Date"])
    aggr.attrs["AggregateEndingTime"] = text_attr(an["Ending_Time"])
    aggr.attrs["AggregateEndingGranuleID"] = text_attr(an["N_Granule_ID"])
    aggr.attrs["AggregateEndingOrbitNumber"] = number_attr(an["N_Beginning_Orbit_Number"], np.uint64)
    aggr.attrs["AggregateNumberGranules"] = number_attr(len(pd.granule_attrs), np.uint64)
    for k, attrs in enumerate(pd.granule_attrs):
        regions = []
        for d in refs:
            n = pd.granule_rows.get(d.name.rsplit("/", 1)[-1])
            regions.append(d.regionref[k * n : (k + 1) * n] if n else d.regionref[...])
        gran = dp.create_dataset(f"{coll}_Gran_{k}", data=np.array(regions, dtype=h5py.regionref_dtype))
        for key, value in attrs.items():
            if key == "N_Beginning_Orbit_Number" or key.endswith("_IET"):
                gran.attrs[key] = number_attr(value, np.uint64)
            elif key == "N_Number_Of_Scans":
                gran.attrs[key] = number_attr(value, np.int32)
            elif key == "Ascending/Descending_Indicator":
                gran.attrs[key] = number_attr(value, np.uint8)
            elif isinstance(value, float):
                gran.attrs[key] = number_attr(value, np.float32)
            else:
                gran.attrs[key] = _attr(value)


def _default_fill(dtype: np.dtype) -> float | int:
    if dtype.kind == "f":
        return -999.3
    if dtype == np.uint8:
        return 249
    if dtype == np.uint16:
        return 65529
    return -993
