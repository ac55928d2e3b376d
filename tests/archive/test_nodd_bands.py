"""The M bands from NODD: listed in their own folders, read in place (only the datasets the mapping reads
travel), and the daily run's mapping on a day read from a real S3-compatible server on loopback."""

import datetime as dt

import numpy as np
import pytest

from benchmarks.servers import MotoS3
from monitor.archive import band_products
from monitor.archive.configured import make_source
from monitor.assessment import compute_day
from monitor.config.file import load_config
from monitor.core.bands import BANDS
from monitor.core.satellites import SATELLITES
from monitor.core.vocabulary import RunStatus
from monitor.sdr import read_file

pytestmark = pytest.mark.servers

DAY = dt.date(2024, 6, 1)
BUCKET = SATELLITES["j01"].bucket


@pytest.fixture(scope="module")
def moto(cases):
    out, _, _ = cases.get(bands=tuple(BANDS))
    with MotoS3() as s3:
        s3.put_granules(BUCKET, sorted(out.glob("*.h5")))
        yield s3, out


def _config(tmp_path, url):
    config = tmp_path / "nodd.yaml"
    config.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
        f"source: {{kind: nodd, endpoint: '{url}/{{bucket}}', retries: 1, backoff_s: 0.01, read: ranges}}\n"
        "scenes: {min_inhomogeneity_k: 0}\nfingerprint: {granules: 2}\n"
        f"mapping_dir: {tmp_path / 'maps'}\nmapping_bands: [I5, M15, M16]\n"
    )
    return load_config(config)


def test_an_m_band_granule_read_in_place_fetches_only_what_the_band_needs(moto, tmp_path):
    s3, out = moto
    cfg = _config(tmp_path, s3.url)
    src = make_source(cfg)
    listed = src.list_day("j01", DAY, band_products("M15"))
    sdr = next(f for f in listed if f.product == "SVM15")
    assert {f.product for f in listed} == {"SVM15", "GMTCO"}
    before = src.spent_bytes
    (g,) = read_file(src.fetch(sdr), kinds=("viirs_sdr",))
    spent = src.spent_bytes - before
    whole = (out / sdr.name).stat().st_size
    assert np.isfinite(g.bt_k).mean() > 0.8
    assert 0 < spent < 0.7 * whole, (spent, whole)  # BT and quality travel; Radiance stays in the archive


def test_the_daily_run_maps_a_day_read_from_nodd(moto, tmp_path):
    s3, _ = moto
    cfg = _config(tmp_path, s3.url)
    work = compute_day(cfg, make_source(cfg), "j01", DAY)
    assert work.status == RunStatus.OK, work.reason
    m = work.mapping
    assert m is not None and m.bands == ("I5", "M15", "M16") and m.geolocation == "assessed"
    for b, band in enumerate(m.bands):
        d = m.values["cris_bt_k"][b] - m.values["viirs_bt_k"][b]
        uniform = m.values["viirs_bt_std_k"][b] < 0.5
        assert uniform.sum() > 100 and abs(np.nanmedian(d[uniform])) < 0.05, band
