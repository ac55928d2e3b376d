"""Readers for JPSS IDPS HDF5 products (CrIS SDR/GEO, VIIRS I5 SDR and I-band GEO). Files, not frames."""

from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import (
    CrisGeoGranule,
    CrisSdrGranule,
    GranuleMeta,
    ViirsGeoGranule,
    ViirsSdrGranule,
)
from monitor.sdr.readers import read_file

__all__ = [
    "GranuleError",
    "GranuleMeta",
    "CrisGeoGranule",
    "CrisSdrGranule",
    "ViirsGeoGranule",
    "ViirsSdrGranule",
    "read_file",
]
