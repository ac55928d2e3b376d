import numpy as np
import pytest

from monitor.core.errors import DataError
from monitor.instrument.spectral import BandModel, apodize_hamming, i5_band, load_srf, planck_radiance


@pytest.mark.parametrize("sat", ["npp", "j01", "j02"])
def test_srf_inside_cris_lw_band(sat):
    nu, s = load_srf(sat)
    band = i5_band(sat)
    half = band.wavenumber_cm1[band.response >= 0.5 * band.response.max()]
    assert 800 < half.min() < 815 and 940 < half.max() < 955
    assert np.all(np.diff(nu) > 0) and s.max() == pytest.approx(1.0, abs=0.01)


def test_blackbody_spectrum_gives_its_temperature():
    band = i5_band("npp")
    for t in (200.0, 255.5, 310.0):
        spec = planck_radiance(band.wavenumber_cm1, t)
        assert band.bt_from_radiance(band.cris_band_radiance(spec)) == pytest.approx(t, abs=2e-3)
        assert band.bt_from_radiance(band.radiance_from_bt(t)) == pytest.approx(t, abs=1e-4)


def test_band_radiance_is_not_a_single_channel_planck():
    band = i5_band("j01")
    spec = 0.5 * planck_radiance(band.wavenumber_cm1, 300.0) + 0.5 * planck_radiance(
        band.wavenumber_cm1, 220.0
    )
    bt = band.bt_from_radiance(band.cris_band_radiance(spec))
    assert 220 < bt < 300 and abs(bt - 260.0) > 5  # radiance mixing is not temperature mixing


def test_hamming_keeps_smooth_spectra_and_out_of_table_is_nan():
    x = np.linspace(1, 2, 50)
    assert np.allclose(apodize_hamming(x)[1:-1], x[1:-1])
    assert np.isnan(i5_band("j01").radiance_from_bt(400.0))
    with pytest.raises(DataError, match="no I5 spectral response"):
        BandModel("metop")


@pytest.mark.parametrize("sat", ["npp", "j01"])
def test_bt_from_radiance_is_np_interp_bit_for_bit(sat):
    """The compiled inversion gives np.interp's numbers: random radiances within and beyond the table, the
    table's own points and their neighbours, NaN and infinities, in any shape."""
    band = i5_band(sat)
    table = band.radiance_table[2]
    rng = np.random.default_rng(5)
    x = np.concatenate(
        [
            rng.uniform(table[0] * 0.9, table[-1] * 1.1, 200_000),
            table,
            np.nextafter(table, 0.0),
            np.nextafter(table, np.inf),
            [np.nan, np.inf, -np.inf, 0.0, -1.0],
        ]
    )
    t = np.arange(band.T_MIN_K, band.T_MAX_K + band.T_STEP_K / 2, band.T_STEP_K)
    expected = np.interp(x, table, t, left=np.nan, right=np.nan)
    np.testing.assert_array_equal(band.bt_from_radiance(x), expected)
    grid = x[: 200 * 7].reshape(200, 7)[:, ::2]  # a strided view
    np.testing.assert_array_equal(band.bt_from_radiance(grid), expected[: 200 * 7].reshape(200, 7)[:, ::2])
    assert band.bt_from_radiance(float(x[0])) == expected[0] and np.ndim(band.bt_from_radiance(x[0])) == 0
    few = x[:: len(x) // 1000]  # below PARALLEL_FROM: the serial kernel
    np.testing.assert_array_equal(band.bt_from_radiance(few), expected[:: len(x) // 1000])
