"""The Grafana dashboards as the configuration says: their specification thresholds from ``alerts.spec_km``.

The shipped dashboards (``configs/grafana/``) are the rendering at the default specification; ``crisgeo
install-files --config FILE`` writes them at the configured one, so that the lines a reviewer reads on a
panel and the rule that pages agree (one definition of "out of spec": :meth:`ForOffset.spec_breaches`).
"""

from __future__ import annotations

import copy
import re
from typing import Any

SPEC_TEXT = re.compile(r"\+-[0-9.]+ km specification")


def _spec_steps(panel: dict[str, Any]) -> list[dict[str, Any]] | None:
    """The threshold steps of a panel in km that mark a specification: below, within, above (None
    elsewhere)."""
    defaults = panel.get("fieldConfig", {}).get("defaults", {})
    steps = defaults.get("thresholds", {}).get("steps", [])
    values = [s.get("value") for s in steps]
    if defaults.get("unit") != "lengthkm" or len(values) != 3 or values[0] is not None:
        return None
    low, high = values[1:]
    return (
        steps if isinstance(low, (int, float)) and isinstance(high, (int, float)) and low == -high else None
    )


def with_specification(dashboard: dict[str, Any], spec_km: float) -> dict[str, Any]:
    """*dashboard* (Grafana's JSON model) with every specification threshold at +-*spec_km* and every
    description that states it saying so.

    Parameters
    ----------
    dashboard : dict
        A Grafana dashboard's JSON model; left unchanged.
    spec_km : float
        The specification of the geolocation error on the ground, km (``alerts.spec_km``).

    Returns
    -------
    dict
        A copy with the thresholds and descriptions set.
    """
    out = copy.deepcopy(dashboard)
    for panel in out.get("panels", []):
        steps = _spec_steps(panel)
        if steps is not None:
            steps[1]["value"], steps[2]["value"] = -spec_km, spec_km
        if "description" in panel:
            panel["description"] = SPEC_TEXT.sub(f"+-{spec_km:g} km specification", panel["description"])
    return out
