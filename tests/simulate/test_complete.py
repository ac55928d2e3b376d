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
def complete_gzip(tmp_path_factory):
    """One CrIS granule and its VIIRS granule, every dataset, gzip with one chunk per dataset."""
    out = tmp_path_factory.mktemp("complete")
    sim = Simulator(_spec("gzip"))
    names = sim.cris_granule(0, out)
    names += sim.viirs_granule(float(sim.viirs_granule_starts()[0]), out)
    return {n.split("_")[0]: out / n for n in names}


def test_every_real_dataset_one_gzip_chunk_each(complete_gzip):
    for product, path in complete_gzip.items():
        found = _datasets(path)
        assert set(found) == set(REAL[product].split()), product
        assert all(chunks == shape and comp == "gzip" for shape, chunks, comp in found.values()), product
    sizes = {p: path.stat().st_size / 1e6 for p, path in complete_gzip.items()}
    assert sizes["GITCO"] > 150 and sizes["SVI05"] > 25  # computed angles do not compress away


def test_the_view_angles_are_computed(complete_gzip):
    with h5py.File(complete_gzip["GITCO"]) as h5:
        g = h5["All_Data/VIIRS-IMG-GEO-TC_All"]
        zen, rng = g["SatelliteZenithAngle"][16], g["SatelliteRange"][16]
    assert zen[3200] < 1.0 and 55 < zen[0] < 75 and 55 < zen[-1] < 75  # nadir, and the swath edges
    assert 8.0e5 < rng[3200] < 8.5e5 and rng[0] > 1.5e6 and rng[-1] > 1.5e6


def test_the_readers_read_complete_files(complete_gzip):
    (g,) = read_file(complete_gzip["GITCO"], kinds=("viirs_geo",))
    (s,) = read_file(complete_gzip["SVI05"], kinds=("viirs_sdr",))
    assert np.isfinite(g.lat_rad).mean() > 0.8 and np.isfinite(s.bt_k).mean() > 0.8  # less the bow-tie
    (c,) = read_file(complete_gzip["SCRIF"], kinds=("cris_sdr",))
    assert c.radiance_lw.shape == (4, 30, 9, 717)


def test_the_contiguous_layout_compresses_nothing(tmp_path):
    names = Simulator(_spec("contiguous")).cris_granule(0, tmp_path)
    for name in names:
        found = _datasets(tmp_path / name)
        assert set(found) == set(REAL[name.split("_")[0]].split())
        assert all(chunks is None and comp is None for _, chunks, comp in found.values())
