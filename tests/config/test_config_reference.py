"""The reference and the JSON Schema are generated from the model, and the shipped files are their output."""

import json

import pytest
import yaml

from monitor.config.file import json_schema, load_config
from monitor.config.keys import ConfigError
from monitor.config.reference import model_keys, reference
from tests.invoke import ROOT

DOCS = ROOT / "docs"


def test_every_key_has_a_meaning():
    assert all(k.field.description for k in model_keys())


def test_the_shipped_reference_and_schema_are_the_generated_ones():
    assert (DOCS / "configuration.md").read_text() == reference(), (
        "regenerate: crisgeo check-config --reference > docs/configuration.md"
    )
    assert (DOCS / "crisgeo-config.schema.json").read_text() == json_schema(), (
        "regenerate: crisgeo check-config --schema > docs/crisgeo-config.schema.json"
    )


def test_the_schema_accepts_the_shipped_configurations_and_refuses_a_bad_one():
    """What an editor does with the schema: the demo file validates, an unknown key and a number out of
    range do not (the same verdicts as the loader)."""
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(json_schema())
    demo = yaml.safe_load((ROOT / "configs" / "demo.yaml").read_text())
    jsonschema.validate(demo, schema)
    for bad in ({**demo, "colour": "blue"}, {**demo, "scenes": {"keep": 0}}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(bad, schema)


@pytest.mark.parametrize("key", sorted(k.name for k in model_keys() if "." in k.name and "[]" not in k.name))
def test_every_documented_key_is_one_the_loader_knows(tmp_path, key):
    """A key named in the reference is known to the loader (an unknown key is refused as such); a NUL
    character or a value of the wrong kind is refused naming that key."""
    *sections, name = key.split(".")
    doc = {
        "satellites": ["j01"],
        "state_dir": "s",
        "source": {"kind": "local" if key == "source.path" else "simulated"},
        "alerts": {
            "email": {"host": "smtp.example.org", "to": ["sdr@example.org"]},
            "slack": {"webhook_env": "HOOK"},
            "alertmanager": {"url": "http://127.0.0.1:9093"},
        },
    }
    node = doc
    for s in sections:
        node = node.setdefault(s, {})
    node[name] = ["\x00"] if key in ("fingerprint.ep_library", "alerts.email.to") else "\x00 unlikely value"
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ConfigError) as exc:
        load_config(path)
    assert "unknown key" not in str(exc.value) and str(exc.value).startswith(key), str(exc.value)
