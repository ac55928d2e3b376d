"""Each per-FOR field is declared once (monitor.core.result.measured): a field declared on a record that
extends ForOffset is found, with its unit, in every output derived from the declaration."""

import dataclasses
import datetime as dt
from pathlib import Path

import numpy as np
import pytest

from monitor.core.measures import Family, measured
from monitor.core.result import NAN, ForOffset, measures
from monitor.core.tables import field_column, text_table
from monitor.history.records import ForSeries
from monitor.service.outputs.metrics import _StoreCollector
from monitor.service.outputs.timeseries import result_lines
from monitor.service.store.schema import result_columns
from monitor.service.store.sqlite import Store

STRAY = Family("crisgeo_for_stray_light_kelvin", "Latest stray light per FOR")


@dataclasses.dataclass(frozen=True)
class WithStrayLight(ForOffset):
    """A FOR record with one field more, declared as ForOffset declares its own."""

    stray_light_k: float = measured("K", "stray light in the I5 band", NAN, metric=(STRAY, ""))


def _fors(n=30):
    return [WithStrayLight(k, 10.0, -5.0, 3.0, 4.0, 0.01, -0.005, 0.011, 0.001, 0.001, 99, 0.2, 0.9,
                           stray_light_k=0.25 + k) for k in range(1, n + 1)]  # fmt: skip


def test_the_declaration_names_unit_and_meaning():
    m = {m.name: m for m in measures(WithStrayLight)}
    assert m["stray_light_k"].unit == "K" and m["stray_light_k"].kind is float
    assert m["n_samples"].kind is int and m["sigma_alpha_urad"].quality
    assert [x.name for x in measures()] == [x.name for x in measures(WithStrayLight)][:-1]


def test_a_new_field_reaches_the_store_columns(tmp_path):
    with Store(tmp_path / "s.sqlite") as store:
        have = set(store.result_column_types())
        assert {m.name for m in measures()} <= have  # every declared field has its column
        assert result_columns(have, WithStrayLight) == ["ALTER TABLE results ADD COLUMN stray_light_k REAL"]
        assert store.add_result_columns(WithStrayLight) == [
            "ALTER TABLE results ADD COLUMN stray_light_k REAL"
        ]
        assert store.add_result_columns(WithStrayLight) == []  # once
        cols = store.result_column_types()
    assert cols["stray_light_k"] == "REAL" and cols["n_samples"] == "INTEGER"


def test_a_new_field_reaches_the_time_series_lines():
    lines = result_lines("cris_geolocation", "j01", dt.date(2026, 1, 2), _fors(2))
    assert "stray_light_k=1.25" in lines[0] and "n_samples=99i" in lines[0]
    assert "sigma_in_track_km" not in lines[0]  # declared series=False


def test_a_new_field_reaches_the_metrics_with_its_unit():
    families = {
        f.name: f for f in _StoreCollector._offsets({"j01": dt.date(2026, 1, 2)}, {"j01": _fors()}, 1.5)
    }
    stray = families["crisgeo_for_stray_light_kelvin"]
    assert stray.documentation == "Latest stray light per FOR"
    assert [s.value for s in stray.samples][:2] == [1.25, 2.25]
    radians = families["crisgeo_for_offset_radians"].samples
    assert {s.labels["direction"] for s in radians} == {"alpha", "beta"}
    assert radians[0].value == pytest.approx(10e-6)  # urad to radians, from the declared unit


def test_a_new_field_reaches_the_tables_with_its_unit():
    lines = text_table(_fors(1), [field_column("stray", "stray_light_k", ".2f", 6, WithStrayLight)])
    assert lines == [" stray", "     K", "  1.25"]


def test_a_new_field_reaches_the_export_with_its_unit_and_meaning():
    pytest.importorskip("xarray")
    from monitor.service.outputs.export import to_xarray

    fors = _fors()
    values = {m.name: np.array([[getattr(f, m.name) for f in fors]]) for m in measures(WithStrayLight)}

    class OneDay:
        path = Path("one-day.sqlite")

        def series(self, satellite, since=None, until=None):
            flags = np.empty((1, 30), object)
            flags.fill(())
            return ForSeries([dt.date(2026, 1, 2)], values, flags, np.ones((1, 30), bool))

    ds = to_xarray(OneDay(), "j01", record=WithStrayLight)
    assert ds["stray_light_k"].attrs["units"] == "K"
    assert ds["stray_light_k"].attrs["long_name"] == "stray light in the I5 band"
    assert float(ds["stray_light_k"][0, 0]) == 1.25 and ds["n_samples"].dtype == np.int32
