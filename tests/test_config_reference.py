"""The configuration reference covers every key of the model, and docs/configuration.md is its output."""

from pathlib import Path

import pytest
import yaml

from monitor.config import ConfigError, load_config
from monitor.config_reference import MEANING, model_keys, reference

DOC = Path(__file__).resolve().parent.parent / "docs" / "configuration.md"


def test_every_key_of_the_model_has_a_meaning_and_nothing_else_does():
    assert set(model_keys()) == set(MEANING)


def test_the_shipped_reference_is_the_generated_one():
    assert DOC.read_text() == reference(), (
        "regenerate: crisgeo check-config --reference > docs/configuration.md"
    )
    for key in model_keys():
        assert f"| `{key}` |" in DOC.read_text()


@pytest.mark.parametrize("key", sorted(k for k in model_keys() if "." in k and "[]" not in k))
def test_every_documented_key_is_one_the_loader_knows(tmp_path, key):
    """A key named in the reference is known to the loader (an unknown key is refused as such), so the
    model's key list and the loader agree; a NUL character in a value is refused whatever the key."""
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
    node[name] = ["\x00"] if key == "fingerprint.ep_library" else "\x00 unlikely value"
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ConfigError) as exc:
        load_config(path)
    assert "unknown key" not in str(exc.value) and str(exc.value).startswith(f"{key}: "), str(exc.value)
