"""How high a simulated cloud top stands: the law that turns its temperature into a height.

A cloud top emits at the temperature of the air around it, so its height is where the atmosphere's
temperature profile T(z) reaches the top's temperature. The profile starts from the surface air
temperature below the cloud, ``T(z) = T_air + (P(z) - P(0))``, and the law is the shape P:

- ``ground``: every cloud lies on the ground (no parallax);
- ``lapse:G``: a linear profile, G K/km (6.5 is the standard atmosphere's);
- ``tropical``: the tropical standard atmosphere (McClatchey et al. 1972, AFCRL-72-0497, table 1a), whose
  lapse rate runs from 4 K/km near 2 km to 7 K/km aloft: not linear.

Tops colder than the profile's coldest stand at :data:`CEILING_M`, the tropical tropopause; tops warmer
than the air below lie on the ground. Heights are above sea level; over terrain a cloud stands only where
its height is above the ground.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.errors import DataError

CEILING_M = 17_000.0
# the tropical standard atmosphere's temperature (K) at 0, 1, ..., 17 km
TROPICAL_K = (300, 294, 288, 284, 277, 270, 264, 257, 250, 244, 237, 230, 224, 217, 210, 204, 197, 195)
LAWS = ("ground", "lapse:G", "tropical")


@dataclass(frozen=True)
class CloudHeights:
    """A cloud-height law (module docstring): *law* one of ``ground``, ``lapse``, ``tropical``, with the
    lapse rate *lapse_k_per_km* for ``lapse``."""

    law: str = "ground"
    lapse_k_per_km: float = 0.0

    @classmethod
    def parse(cls, text: str) -> CloudHeights:
        """The law written as ``ground``, ``lapse:6.5`` (K/km, > 0) or ``tropical``.

        Parameters
        ----------
        text : str
            The law.

        Returns
        -------
        CloudHeights
            The law; a ValueError names what is wrong.
        """
        name, _, value = text.partition(":")
        if name in ("ground", "tropical") and not value:
            return cls(name)
        if name == "lapse":
            try:
                rate = float(value)
            except ValueError:
                rate = float("nan")
            if rate > 0 and np.isfinite(rate):
                return cls("lapse", rate)
        raise DataError(f"cloud heights {text!r}: not one of {', '.join(LAWS)} (G in K/km, > 0)")

    def __str__(self) -> str:
        return f"lapse:{self.lapse_k_per_km:g}" if self.law == "lapse" else self.law

    @property
    def flat(self) -> bool:
        """Whether every cloud lies on the ground.

        Returns
        -------
        bool
            True on the ground.
        """
        return self.law == "ground"

    def knots(self) -> tuple[np.ndarray, np.ndarray]:
        """The law as knots of a piecewise-linear function: (cooling below the surface air K, increasing;
        height m), held at its ends beyond them (on the ground when warmer, at the ceiling when colder).

        Returns
        -------
        cooling_k, height_m : numpy.ndarray
            The knots.
        """
        if self.law == "ground":
            return np.array([0.0, 1.0]), np.zeros(2)
        if self.law == "lapse":
            return np.array([0.0, CEILING_M / 1000.0 * self.lapse_k_per_km]), np.array([0.0, CEILING_M])
        cooling = TROPICAL_K[0] - np.asarray(TROPICAL_K, float)
        return cooling, np.minimum(np.arange(len(TROPICAL_K)) * 1000.0, CEILING_M)

    def top_height_m(self, top_k: ArrayLike, air_k: ArrayLike) -> np.ndarray:
        """Height (m above sea level) of cloud tops at *top_k* (K) over surface air at *air_k* (K).

        Parameters
        ----------
        top_k : array_like
            Cloud-top temperature, K.
        air_k : array_like
            Surface air temperature, K.

        Returns
        -------
        numpy.ndarray
            m above sea level.
        """
        cooling_k = np.asarray(air_k, float) - np.asarray(top_k, float)
        return np.interp(cooling_k, *self.knots()).astype(np.float32)


FLAT = CloudHeights()  # every cloud on the ground
