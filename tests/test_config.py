from pathlib import Path

import pytest

from monitor.config import ConfigError, load_config

CONFIGS = Path(__file__).resolve().parent.parent / "configs"


def test_shipped_configs_load():
    demo = load_config(CONFIGS / "demo.yaml")
    assert demo.source.kind == "simulated" and demo.store.publish == [] and demo.satellites == ["j01"]
    prod = load_config(CONFIGS / "monitor.yaml")
    assert prod.source.kind == "nodd" and prod.satellites == ["npp", "j01", "j02"]
    assert prod.store.publish[0].kind == "influx1" and prod.store.publish[0].password_env == "CRISGEO_INFLUX_PASSWORD"
    assert prod.schedule.time_utc.hour == 6


def _write(tmp_path, text):
    p = tmp_path / "c.yaml"
    p.write_text(text)
    return p


BASE = "satellites: [j01]\nstate_dir: s\nsource: {kind: simulated}\n"


@pytest.mark.parametrize("text,message", [
    ("state_dir: s\nsource: {kind: simulated}\n", "satellites: missing"),
    ("satellites: [j05]\nstate_dir: s\nsource: {kind: simulated}\n", "satellites[0]: 'j05' is not one of"),
    (BASE + "schedule: {time_utc: '25:00'}\n", "schedule.time_utc: '25:00' is not HH:MM"),
    (BASE + "scenes: {keep: 0}\n", "scenes.keep: must be > 0"),
    (BASE + "scenes: {keep: ten}\n", "scenes.keep: expected int, got str"),
    (BASE + "store: {publish: [{kind: influx2, url: 'localhost:8086'}]}\n", "store.publish[0].url"),
    (BASE + "store: {publish: [{kind: influx2, url: 'http://h', token: abc}]}\n", "secrets may not be written"),
    (BASE + "colour: blue\n", "colour: unknown key"),
    ("satellites: [j01]\nstate_dir: s\nsource: {kind: local}\n", "source.path: missing"),
    ("- a\n- b\n", "expected a mapping"),
])
def test_errors_name_the_key(tmp_path, text, message):
    with pytest.raises(ConfigError) as e:
        load_config(_write(tmp_path, text))
    assert message in str(e.value)


def test_secret_comes_from_environment(tmp_path, monkeypatch):
    cfg = load_config(_write(tmp_path, BASE + "store: {publish: [{kind: influx2, url: 'http://h', token_env: TOK}]}\n"))
    monkeypatch.setenv("TOK", "s3cret")
    assert cfg.store.publish[0].secret("token_env") == "s3cret"
    assert cfg.state_dir == tmp_path / "s"  # relative to the file
