"""The simulator writes every dataset of the real products (docs/jpss-formats.md 1.4-1.8) in either
layout, and the readers read such files as they read the reduced ones."""

import h5py
import numpy as np
import pytest

from monitor.sdr import read_file
from monitor.simulate.case import SimulationSpec, Simulator
from monitor.simulate.profiles import load_profile

# the dataset lists of the fact sheet
REAL = {
    "GCRSO": """FORTime StartTime MidTime Latitude Longitude Height SatelliteRange SatelliteZenithAngle
        SatelliteAzimuthAngle SolarZenithAngle SolarAzimuthAngle SCPosition SCVelocity SCAttitude
        QF1_CRISSDRGEO PadByte1""",
    "SCRIF": """DS_SpectralStability DS_Symmetry DS_WindowSize ES_ImaginaryLW ES_ImaginaryMW ES_ImaginarySW
        ES_NEdNLW ES_NEdNMW ES_NEdNSW ES_RDRImpulseNoise ES_RealLW ES_RealMW ES_RealSW ES_ZPDAmplitude
        ES_ZPDFringeCount ICT_SpectralStability ICT_TemperatureConsistency ICT_TemperatureStability
        ICT_WindowSize MeasuredLaserWavelength MonitoredLaserWavelength NumberOfValidPRTTemps QF1_SCAN_CRISSDR
        QF2_CRISSDR QF3_CRISSDR QF4_CRISSDR ResamplingLaserWavelength SDRFringeCount""",
    "SVI05": """BrightnessTemperature BrightnessTemperatureFactors Radiance RadianceFactors QF1_VIIRSIBANDSDR
        QF2_SCAN_SDR QF3_SCAN_RDR QF4_SCAN_SDR QF5_GRAN_BADDETECTOR ModeGran ModeScan NumberOfScans
        NumberOfMissingPkts NumberOfBadChecksums NumberOfDiscardedPkts PadByte1""",
    "GITCO": """Latitude Longitude Height SatelliteZenithAngle SatelliteAzimuthAngle SatelliteRange
        SolarZenithAngle SolarAzimuthAngle QF2_VIIRSSDRGEO StartTime MidTime SCPosition SCVelocity SCAttitude
        SCSolarAzimuthAngle SCSolarZenithAngle QF1_SCAN_VIIRSSDRGEO ModeGran ModeScan NumberOfScans
        PadByte1""",
}


def _spec(layout, granules=1):
    d_alpha, d_beta = load_profile("paper", 1)
    return SimulationSpec(
        granules=granules,
        d_alpha_urad=np.asarray(d_alpha, float),
        d_beta_urad=np.asarray(d_beta, float),
        seed=1,
        complete=True,
        layout=layout,
    )


def _datasets(path):
    with h5py.File(path) as h5:
        group = h5["All_Data"][next(iter(h5["All_Data"]))]
        return {name: (ds.shape, ds.chunks, ds.compression) for name, ds in group.items()}


@pytest.fixture(scope="module")
def complete(tmp_path_factory):
    """One CrIS granule and its VIIRS granule, every dataset, uncompressed (the gzip layout writes the
    same arrays through the same writer: tested on CrIS files below, ~15 s cheaper)."""
    out = tmp_path_factory.mktemp("complete")
    sim = Simulator(_spec("contiguous"))
    names = sim.cris_granule(0, out)
    names += sim.viirs_granule(float(sim.viirs_granule_starts()[0]), out)
    return {n.split("_")[0]: out / n for n in names}


def test_every_real_dataset_at_real_size(complete):
    for product, path in complete.items():
        found = _datasets(path)
        assert set(found) == set(REAL[product].split()), product
        assert all(chunks is None and comp is None for _, chunks, comp in found.values()), product
    sizes = {p: path.stat().st_size / 1e6 for p, path in complete.items()}
    assert 320 < sizes["GITCO"] < 330 and 48 < sizes["SVI05"] < 50 and 0.05 < sizes["GCRSO"] < 0.2


def test_the_view_angles_are_computed(complete):
    with h5py.File(complete["GITCO"]) as h5:
        g = h5["All_Data/VIIRS-IMG-GEO-TC_All"]
        zen, rng = g["SatelliteZenithAngle"][16], g["SatelliteRange"][16]
    assert zen[3200] < 1.0 and 55 < zen[0] < 75 and 55 < zen[-1] < 75  # nadir, and the swath edges
    assert 8.0e5 < rng[3200] < 8.5e5 and rng[0] > 1.5e6 and rng[-1] > 1.5e6


def test_the_readers_read_complete_files(complete):
    (g,) = read_file(complete["GITCO"], kinds=("viirs_geo",))
    (s,) = read_file(complete["SVI05"], kinds=("viirs_sdr",))
    assert np.isfinite(g.lat_rad).mean() > 0.8 and np.isfinite(s.bt_k).mean() > 0.8  # less the bow-tie
    (c,) = read_file(complete["SCRIF"], kinds=("cris_sdr",))
    assert c.radiance_lw.shape == (4, 30, 9, 717)


def test_the_gzip_layout_is_one_chunk_per_dataset(tmp_path):
    names = Simulator(_spec("gzip")).cris_granule(0, tmp_path)
    for name in names:
        found = _datasets(tmp_path / name)
        assert set(found) == set(REAL[name.split("_")[0]].split())
        assert all(chunks == shape and comp == "gzip" for shape, chunks, comp in found.values())
    (c,) = read_file(tmp_path / next(n for n in names if n.startswith("SCRIF")), kinds=("cris_sdr",))
    assert np.isfinite(c.radiance_lw).all()
