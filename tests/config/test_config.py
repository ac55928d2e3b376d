import pytest

from monitor.config.file import load_config
from monitor.config.keys import ConfigError
from tests.invoke import ROOT

CONFIGS = ROOT / "configs"


def test_shipped_configs_load(tmp_path):
    demo = load_config(CONFIGS / "demo.yaml")
    assert demo.source.kind == "simulated" and demo.store.publish == [] and demo.satellites == ["j01"]
    # the production file names /var/lib/crisgeo and /etc/crisgeo: here, folders of the test's own
    (tmp_path / "events.yaml").write_text((CONFIGS / "events.yaml").read_text())
    text = (CONFIGS / "monitor.yaml").read_text()
    assert "/var/lib/crisgeo" in text and "/etc/crisgeo/events.yaml" in text
    prod_file = tmp_path / "monitor.yaml"
    prod_file.write_text(
        text.replace("/var/lib/crisgeo", str(tmp_path / "state")).replace(
            "/etc/crisgeo/events.yaml", str(tmp_path / "events.yaml")
        )
    )
    prod = load_config(prod_file)
    assert prod.source.kind == "nodd" and prod.satellites == ["npp", "j01", "j02"]
    assert (
        prod.store.publish[0].kind == "influx1"
        and prod.store.publish[0].password_env == "CRISGEO_INFLUX_PASSWORD"
    )
    assert prod.schedule.time_utc.hour == 6


def _write(tmp_path, text):
    p = tmp_path / "c.yaml"
    p.write_text(text)
    return p


BASE = "satellites: [j01]\nstate_dir: s\nsource: {kind: simulated}\n"


@pytest.mark.parametrize(
    "text,message",
    [
        ("state_dir: s\nsource: {kind: simulated}\n", "satellites: missing"),
        (
            "satellites: [j05]\nstate_dir: s\nsource: {kind: simulated}\n",
            "satellites[0]: 'j05' is not one of",
        ),
        (BASE + "schedule: {time_utc: '25:00'}\n", "schedule.time_utc: '25:00' is not HH:MM"),
        (BASE + "scenes: {keep: 0}\n", "scenes.keep: 0 is not within 1..200"),
        (BASE + "scenes: {keep: ten}\n", "scenes.keep: expected int, got str"),
        (BASE + "store: {publish: [{kind: influx2, url: 'localhost:8086'}]}\n", "store.publish[0].url"),
        (
            BASE + "store: {publish: [{kind: influx2, url: 'http://h', token: abc}]}\n",
            "secrets may not be written",
        ),
        (BASE + "colour: blue\n", "colour: unknown key"),
        ("satellites: [j01]\nstate_dir: s\nsource: {kind: local}\n", "source.path: missing"),
        ("- a\n- b\n", "expected a mapping"),
    ],
)
def test_errors_name_the_key(tmp_path, text, message):
    with pytest.raises(ConfigError) as e:
        load_config(_write(tmp_path, text))
    assert message in str(e.value)


def test_secret_comes_from_environment(tmp_path, monkeypatch):
    cfg = load_config(
        _write(tmp_path, BASE + "store: {publish: [{kind: influx2, url: 'http://h', token_env: TOK}]}\n")
    )
    monkeypatch.setenv("TOK", "s3cret")
    assert cfg.store.publish[0].secret("token_env") == "s3cret"
    assert cfg.state_dir == tmp_path / "s"  # relative to the file


GOOD = {
    "satellites": ["j01"],
    "state_dir": "state",
    "source": {"kind": "nodd"},
    "store": {"publish": [{"kind": "influx2", "url": "http://127.0.0.1:8428", "token_env": "T"}]},
    "alerts": {
        "log": "alerts.log",
        "email": {"host": "smtp.example.org", "to": ["a@example.org"]},
        "slack": {"webhook_env": "SLACK"},
    },
}
BAD = [  # (where, value or a function of the document, the key the one-line error must name)
    ("satellites", [], "satellites"),
    ("satellites", ["j01", "j01"], "satellites"),
    ("satellites", "j01", "satellites"),
    ("satellites", [1], "satellites[0]"),
    ("state_dir", 5, "state_dir"),
    ("source.kind", "ftp", "source.kind"),
    ("source.timeout_s", float("nan"), "source.timeout_s"),
    ("source.timeout_s", float("inf"), "source.timeout_s"),
    ("source.timeout_s", -1, "source.timeout_s"),
    ("source.timeout_s", 1e9, "source.timeout_s"),
    ("source.timeout_s", "60s", "source.timeout_s"),
    ("source.timeout_s", True, "source.timeout_s"),
    ("source.retries", -1, "source.retries"),
    ("source.retries", 1000, "source.retries"),
    ("source.retries", 2.5, "source.retries"),
    ("source.backoff_s", 0, "source.backoff_s"),
    ("source.daily_budget_mb", float("nan"), "source.daily_budget_mb"),
    ("source.retention_days", -3, "source.retention_days"),
    ("source.run_deadline_min", 0, "source.run_deadline_min"),
    ("source.max_list_pages", 0, "source.max_list_pages"),
    ("source.max_retry_after_s", -5, "source.max_retry_after_s"),
    ("source.min_rate_kb_s", 0, "source.min_rate_kb_s"),
    ("source.endpoint", "ftp://x/{bucket}", "source.endpoint"),
    ("source.endpoint", "https://user:pw@{bucket}.s3.amazonaws.com", "source.endpoint"),
    ("source.endpoint", "https://s3.amazonaws.com", "source.endpoint"),
    ("source.buckets", {"j09": "b"}, "source.buckets.j09"),
    ("source.buckets", {"j01": "Bad Bucket"}, "source.buckets.j01"),
    ("source.buckets", {"j01": 7}, "source.buckets.j01"),
    ("source.colour", "x", "source.colour"),
    ("source.calibration", {"j09": {"gain": 0.01}}, "source.calibration.j09"),
    ("source.calibration", {"j01": {"gain": 0.5}}, "source.calibration.j01.gain"),
    ("source.calibration", {"j01": {"offset_k": 1.0}}, "source.calibration.j01.offset_k"),
    ("schedule.time_utc", "3pm", "schedule.time_utc"),
    ("schedule.time_utc", "24:00", "schedule.time_utc"),
    ("schedule.catch_up_days", 0, "schedule.catch_up_days"),
    ("schedule.catch_up_days", 10000, "schedule.catch_up_days"),
    ("schedule.lag_days", -1, "schedule.lag_days"),
    ("schedule.misfire_grace_hours", float("nan"), "schedule.misfire_grace_hours"),
    ("schedule.every", "day", "schedule.every"),
    ("scenes.keep", 50, "scenes.keep"),
    ("scenes.candidates", -4, "scenes.candidates"),
    ("scenes.min_inhomogeneity_k", -1.0, "scenes.min_inhomogeneity_k"),
    ("assessment.kernel", "gauss", "assessment.kernel"),
    ("assessment.workers", 0, "assessment.workers"),
    ("assessment.workers", 1000, "assessment.workers"),
    ("assessment.half_steps", 500, "assessment.half_steps"),
    ("assessment.half_steps", 30, "assessment.half_steps"),  # wider than the kernel takes
    ("assessment.step_urad", float("inf"), "assessment.step_urad"),
    ("store.drain_minutes", 0, "store.drain_minutes"),
    ("store.backend", "pg", "store.backend"),
    (
        "store.publish",
        [{"kind": "influx2", "url": "http://admin:secret@127.0.0.1:8086"}],
        "store.publish[0].url",
    ),
    ("store.publish", [{"kind": "kafka", "url": "http://h"}], "store.publish[0].kind"),
    ("store.publish", [{"kind": "influx2"}], "store.publish[0].url"),
    ("store.publish", [{"kind": "influx2", "url": "http://h", "token": "abc"}], "store.publish[0].token"),
    (
        "store.publish",
        [{"kind": "influx2", "url": "http://h", "token_env": "my secret token"}],
        "store.publish[0].token_env",
    ),
    (
        "store.publish",
        [{"kind": "influx2", "url": "http://h", "timeout_s": float("nan")}],
        "store.publish[0].timeout_s",
    ),
    ("store.publish", ["http://h"], "store.publish[0]"),
    ("fingerprint.granules", 0, "fingerprint.granules"),
    ("fingerprint.ep_library", 5, "fingerprint.ep_library"),
    ("dashboard_url", "grafana.local", "dashboard_url"),
    ("report_dir", ["a"], "report_dir"),
    ("alerts.spec_km", "abc", "alerts.spec_km"),
    ("alerts.spec_km", float("nan"), "alerts.spec_km"),
    ("alerts.spec_km", -1.5, "alerts.spec_km"),
    ("alerts.stale_hours", 0, "alerts.stale_hours"),
    ("alerts.pre_days", 1.5, "alerts.pre_days"),
    ("alerts.min_pre_days", 100, "alerts.min_pre_days"),
    ("alerts.practical_step_urad", float("inf"), "alerts.practical_step_urad"),
    ("alerts.colour", "red", "alerts.colour"),
    ("alerts.email", "smtp.example.org", "alerts.email"),
    ("alerts.email.port", 70000, "alerts.email.port"),
    ("alerts.email.to", "a@example.org", "alerts.email.to"),
    ("alerts.email.to", ["nobody"], "alerts.email.to[0]"),
    ("alerts.email.starttls", "yes", "alerts.email.starttls"),
    ("alerts.email.password", "x", "alerts.email.password"),
    ("alerts.email.tls", True, "alerts.email.tls"),
    ("alerts.slack.webhook", "https://hooks.slack.com/x", "alerts.slack.webhook"),
    ("alerts.slack.webhook_env", "https://hooks.slack.com/services/x", "alerts.slack.webhook_env"),
    ("alerts.slack.retries", -1, "alerts.slack.retries"),
    ("alerts.slack.timeout_s", float("nan"), "alerts.slack.timeout_s"),
]


def _doc_with(where, value):
    import copy

    doc = copy.deepcopy(GOOD)
    *parents, key = where.split(".")
    d = doc
    for p in parents:
        d = d.setdefault(p, {})
    d[key] = value
    return doc


def test_the_good_document_is_good(tmp_path):
    import yaml

    p = tmp_path / "c.yaml"
    p.write_text(yaml.safe_dump(GOOD))
    assert load_config(p).alerts.channels == ["log", "email", "slack"]


@pytest.mark.parametrize("where,value,key", BAD, ids=[f"{w}={v!r}"[:60] for w, v, _ in BAD])
def test_bad_configurations_are_refused_in_one_line_naming_the_key(tmp_path, capsys, where, value, key):
    import yaml

    from monitor.cli import main

    p = tmp_path / "c.yaml"
    p.write_text(yaml.safe_dump(_doc_with(where, value)))
    assert main(["check-config", "--config", str(p)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"crisgeo check-config: {p}: {key}:"), err
    assert "secret" not in err[0].replace("secrets may not", "") or key.endswith("token")
    assert main(["run", "--config", str(p)]) == 2  # nothing starts on a bad file
    assert not (tmp_path / "state").exists()
    capsys.readouterr()


def test_there_are_at_least_60_bad_configurations():
    assert len(BAD) >= 60


@pytest.mark.parametrize(
    "text,message",
    [
        ("a: &x [1, 2]\nb: *x\n", "line 1: YAML anchors"),
        ("satellites: [j01]\n" + "#" * (1 << 20), "larger than 1 MiB"),
        ("satellites: [\n", "not valid YAML"),
    ],
)
def test_yaml_bombs_and_giants_are_refused(tmp_path, text, message):
    p = _write(tmp_path, text)
    with pytest.raises(ConfigError, match=message):
        load_config(p)


def test_check_config_masks_secrets(tmp_path, capsys, monkeypatch):
    import yaml

    from monitor.cli import main

    monkeypatch.setenv("T", "the-token-value")
    p = tmp_path / "c.yaml"
    p.write_text(yaml.safe_dump(GOOD))
    assert main(["check-config", "--config", str(p)]) == 0
    out = capsys.readouterr().out
    assert "# secret store.publish[0].token_env: T (set)" in out
    assert "# secret alerts.slack.webhook_env: SLACK (not set)" in out
    assert "the-token-value" not in out and "catch_up_days: 7" in out and "spec_km: 1.5" in out


def test_what_check_config_prints_loads_back_as_the_same_configuration(tmp_path, capsys):
    """Before, it printed alerts.dashboard_url (an unknown key there), sender for from, report_dir twice."""
    import yaml

    from monitor.cli import main
    from monitor.config.file import effective

    doc = {
        **GOOD,
        "report_dir": "report",
        "dashboard_url": "http://grafana.example/d/crisgeo-monitor",
        "alerts": {
            **GOOD["alerts"],
            "email": {"host": "smtp.example.org", "from": "me@example.org", "to": ["a@example.org"]},
            "alertmanager": {"url": "http://127.0.0.1:9093"},
        },
    }
    first = tmp_path / "c.yaml"
    first.write_text(yaml.safe_dump(doc))
    assert main(["check-config", "--config", str(first)]) == 0
    printed = capsys.readouterr().out
    assert printed.count("report_dir:") == 1 and "sender" not in printed and "from: me@example.org" in printed
    second = tmp_path / "again" / "c.yaml"
    second.parent.mkdir()
    second.write_text(printed)
    assert main(["check-config", "--config", str(second)]) == 0, capsys.readouterr().err
    assert capsys.readouterr().out.split("\n", 1)[1] == printed.split("\n", 1)[1]
    assert effective(load_config(second)) == effective(load_config(first))


GOOD_TEXT = "satellites: [j01]\nstate_dir: state\nsource: {kind: simulated}\n"
SEVEN = [  # (file text, the key or place the one-line error names): what slipped through before
    (GOOD_TEXT.replace("state_dir: state", "state_dir: /proc/crisgeo-state"), "state_dir:"),
    (GOOD_TEXT.replace("state_dir: state", "state_dir: /sys/crisgeo"), "state_dir:"),
    (GOOD_TEXT + "schedule: {1: a, b: 2}\n", "schedule.1: unknown key"),
    (GOOD_TEXT + "schedule: []\n", "schedule: expected a mapping, got list"),
    (GOOD_TEXT + "alerts: {events_file: nowhere.yaml}\n", "alerts.events_file:"),
    (GOOD_TEXT + "scenes: {keep: 3}\nscenes: {keep: 4}\n", "line 5: key 'scenes' is given twice"),
    (GOOD_TEXT + "scenes: {keep: 3, candidates: 5, keep: 4}\n", "line 4: key 'keep' is given twice"),
    (GOOD_TEXT + "scenes: {keep: 3\n", "not valid YAML: line 5, column 1:"),
    (GOOD_TEXT + "scenes:\n  keep: 3\n    candidates: 4\n", "not valid YAML: line 6, column 15:"),
    ("satellites: [j01]\nstate_dir: state\nsource: {kind: local, path: nowhere}\n", "source.path:"),
]


@pytest.mark.parametrize("text,named", SEVEN, ids=[n.split(":")[0] for _, n in SEVEN])
def test_the_cases_that_slipped_through_are_refused_in_one_line(tmp_path, text, named):
    """A traceback, an acceptance or a several-line message before; now one line naming the file and the
    key (or the YAML line), exit 2, and nothing created."""
    from tests.invoke import run_crisgeo

    p = _write(tmp_path, text)
    r = run_crisgeo("check-config", "--config", p, timeout=60)
    err = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(err) == 1, r.stderr
    assert err[0].startswith(f"crisgeo check-config: {p}: ") and named in err[0], err[0]
    assert "Traceback" not in r.stderr and not (tmp_path / "state").exists()


def test_a_state_dir_that_cannot_be_made_stops_a_run_in_one_line(tmp_path):
    from tests.invoke import run_crisgeo

    (tmp_path / "file").write_text("x")
    p = _write(tmp_path, GOOD_TEXT.replace("state_dir: state", "state_dir: file/state"))
    r = run_crisgeo("run", "--config", p, timeout=60)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "state_dir:" in r.stderr
