"""The inverse geolocation on real NOAA-20 GCRSO granules (2018-10-22), pinning time and frames."""

import numpy as np

from monitor.geometry import frames, orbit
from monitor.geometry.inverse import forward_geolocation, inverse_geolocation, satellite_from_fov
from monitor.geometry.wgs84 import ecef_to_geodetic
from monitor.sdr import read_file


def _geometry(g):
    return inverse_geolocation(
        g.lat_rad,
        g.lon_rad,
        g.zenith_rad,
        g.azimuth_rad,
        g.range_m,
        g.for_time_us,
        g.mid_time_us,
        g.sc_position_m,
        g.sc_velocity_m_s,
        g.sc_attitude_rad,
    )


def test_implied_satellite_matches_propagated_ephemeris(real_geo_files):
    dists, along = [], []
    for f in real_geo_files:
        (g,) = read_file(f)
        _, sat = satellite_from_fov(g.lat_rad, g.lon_rad, g.zenith_rad, g.azimuth_rad, g.range_m)
        r, v = orbit.state_at(g.for_time_us, g.mid_time_us, g.sc_position_m, g.sc_velocity_m_s)
        d = sat - r[:, :, None, :]
        dists.append(np.linalg.norm(d, axis=-1).ravel())
        along.append(np.sum(d * frames.unit(v)[:, :, None, :], axis=-1).ravel())
    dists, along = np.concatenate(dists), np.concatenate(along)
    assert np.percentile(dists, 99) < 50.0
    assert np.max(np.abs(along)) < 2.0  # a 1 ms time error would show as 7.5 m


def test_time_shift_would_be_detected(real_geo_files):
    (g,) = read_file(real_geo_files[0])
    _, sat = satellite_from_fov(g.lat_rad, g.lon_rad, g.zenith_rad, g.azimuth_rad, g.range_m)
    r, v = orbit.state_at(g.for_time_us + 1000, g.mid_time_us, g.sc_position_m, g.sc_velocity_m_s)
    along = np.sum((sat - r[:, :, None, :]) * frames.unit(v)[:, :, None, :], axis=-1)
    assert np.max(np.abs(along)) > 5.0


def test_inverse_then_forward_reproduces_every_fov(real_geo_files):
    worst = 0.0
    for f in real_geo_files:
        (g,) = read_file(f)
        fg = _geometry(g)
        p = forward_geolocation(fg.sat_ecef_m, fg.sbf_to_ecef, fg.los_sbf)
        lat, lon, _ = ecef_to_geodetic(p)
        dist = np.hypot((lat - g.lat_rad) * 6.37e6, (lon - g.lon_rad) * 6.37e6 * np.cos(g.lat_rad))
        worst = max(worst, float(dist.max()))
    assert worst < 1.0


def test_fov5_scan_angles_and_fov_pattern(real_geo_files):
    (g,) = read_file(real_geo_files[0])
    fg = _geometry(g)
    beta5 = np.degrees(fg.beta_rad[:, :, 4]).mean(axis=0)
    assert -48.5 < beta5[0] < -48.0 and 48.2 < beta5[-1] < 48.6  # FOR 1 on the left
    assert np.all(np.diff(beta5) > 3.2)
    # FOV 7-9 lead FOV 1-3 in track at nadir
    assert np.all(fg.alpha_rad[:, 14, 6:9] > fg.alpha_rad[:, 14, 0:3])
    # scan-to-scan stability of the FOV-5 LOS (the fingerprint of the EP angles)
    assert np.max(np.std(fg.alpha_rad[:, :, 4], axis=0)) < 20e-6
