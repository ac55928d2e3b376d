"""Injected CrIS LOS error profiles per FOR (urad): the turn that takes the GEO LOS onto the true one."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import yaml

from monitor.core.constants import FOV_DIAMETER_URAD, N_FOR
from monitor.core.errors import DataError


def paper_profile() -> tuple[np.ndarray, np.ndarray]:
    """The pattern of Wang et al. 2017 figure 7 (S-NPP IDPS before the EP update).

    Cross-track ~0 for FOR 1-10, growing to +1750 urad at FOR 30; in-track a yaw-like ramp from
    +5.1 % of the FOV at FOR 1 to -3 % at FOR 30.

    Returns
    -------
    d_alpha_urad, d_beta_urad : numpy.ndarray
        Shape (30,).
    """
    k = np.arange(1, N_FOR + 1)
    d_beta = 1750.0 * np.clip((k - 10) / 20.0, 0.0, None) ** 2
    d_alpha = FOV_DIAMETER_URAD * np.interp(k, [1, N_FOR], [0.051, -0.03])
    return d_alpha, d_beta


def random_profile(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A smooth random profile within about +-1500 urad (low-order polynomials in scan position).

    Parameters
    ----------
    seed : int
        The generator's seed.

    Returns
    -------
    d_alpha_urad, d_beta_urad : numpy.ndarray
        Shape (30,).
    """
    rng = np.random.default_rng(seed + 7919)
    x = np.linspace(-1.0, 1.0, N_FOR)
    basis = np.stack([np.ones_like(x), x, x**2, x**3])
    d_alpha = rng.uniform(-500, 500, 4) @ basis
    d_beta = rng.uniform(-500, 500, 4) @ basis
    return d_alpha, d_beta


def load_profile(name: str, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(d_alpha_urad, d_beta_urad), each (30,), for *name*: paper, random, zero, or a JSON/YAML file.

    A file holds ``fors: [{for: 1, d_alpha_urad: .., d_beta_urad: ..}, ...]`` (the truth.json and
    result.json layout) or two 30-element lists ``d_alpha_urad`` and ``d_beta_urad``.

    Parameters
    ----------
    name : str
        ``paper``, ``random``, ``zero`` or a file.
    seed : int, optional
        For ``random``.

    Returns
    -------
    d_alpha_urad, d_beta_urad : numpy.ndarray
        Shape (30,).
    """
    if name == "paper":
        return paper_profile()
    if name == "random":
        return random_profile(seed)
    if name == "zero":
        return np.zeros(N_FOR), np.zeros(N_FOR)
    path = Path(name)
    if not path.is_file():
        raise DataError(f"profile {name!r} is neither paper, random, zero nor an existing file")
    try:
        doc = json.loads(path.read_text()) if path.suffix == ".json" else yaml.safe_load(path.read_text())
        if "fors" in doc:
            rows = sorted(doc["fors"], key=lambda r: r["for"])
            d_alpha = np.array([float(r["d_alpha_urad"]) for r in rows])
            d_beta = np.array([float(r["d_beta_urad"]) for r in rows])
        else:
            d_alpha = np.asarray(doc["d_alpha_urad"], float)
            d_beta = np.asarray(doc["d_beta_urad"], float)
    except (ValueError, KeyError, TypeError, AttributeError, yaml.YAMLError) as exc:
        raise DataError(f"{path}: not a profile file ({exc})") from None
    if d_alpha.shape != (N_FOR,) or d_beta.shape != (N_FOR,) or not np.all(np.isfinite(d_alpha + d_beta)):
        raise DataError(f"{path}: a profile needs 30 finite d_alpha_urad and d_beta_urad values")
    return d_alpha, d_beta
