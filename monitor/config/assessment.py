"""The science's sections: ``scenes`` (which granules), ``assessment`` (the grid, the kernel, the cost, the
estimator), ``fingerprint``."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import (
    BeforeValidator,
    Field,
    model_validator,
)

from monitor.config.keys import Band, FilePath, KeyProblem, Section, key
from monitor.core.constants import (
    DEFAULT_HALF_STEPS,
    DEFAULT_STEP_URAD,
    MAX_GRID_SPREAD_RAD,
    PAPER_GRANULES,
    PROCESSING_CHANGE_URAD,
    URAD,
)
from monitor.core.vocabulary import (
    DEFAULT_COST,
    DEFAULT_KERNEL,
    Cost,
    Kernel,
)


class SceneConfig(Section):
    """The ``scenes`` section: which CrIS granules of a day are assessed."""

    candidates: int = key(
        40, "CrIS granules of the day scored for inhomogeneity (spread over the day).", 1, 3000
    )
    keep: int = key(
        PAPER_GRANULES,
        "Granules of the first batch, the most informative per byte first, and the fewest of any later "
        "one; without target_sigma_urad the day's only batch (the paper uses 14).",
        1,
        200,
    )
    min_inhomogeneity_k: float = key(0.5, "A granule whose VIIRS-BT spread is below this is not used.", 0, 50)
    target_sigma_urad: float | None = key(
        None,
        "The day's precision goal: the median per-FOR jackknife sigma (urad, worse direction). Batches "
        "are assessed until it is reached, max_granules are assessed, the candidates are spent, or keep "
        "more granules would pass source.daily_budget_mb or schedule.run_budget_min; after the first "
        "(keep), each takes what 1/sqrt(N) says the target needs, at least keep and at most the day so "
        "far. None: one batch. What a day at a target costs, and which budget ends it first: "
        "docs/operations.md.",
        1.0,
        10000.0,
    )
    max_granules: int = key(
        200,
        "Most granules a day with a target_sigma_urad assesses (at most candidates are scored).",
        1,
        3000,
    )

    @model_validator(mode="after")
    def _consistent(self) -> SceneConfig:
        if self.keep > self.candidates:
            raise KeyProblem("keep", f"{self.keep} is more than scenes.candidates ({self.candidates})")
        if self.keep > self.max_granules:
            raise KeyProblem("keep", f"{self.keep} is more than scenes.max_granules ({self.max_granules})")
        return self


class AssessmentConfig(Section):
    """The ``assessment`` section: the perturbation grid and the collocation."""

    half_steps: int = key(
        DEFAULT_HALF_STEPS,
        "Perturbations on each side of zero per direction: the grid is (2n+1)^2 (21 x 21).",
        1,
        40,
    )
    step_urad: float = key(
        DEFAULT_STEP_URAD,
        "Perturbation step (375 m at nadir from 833 km); half_steps^2 x step_urad <= 200000.",
        10,
        5000,
    )
    kernel: Kernel = key(
        DEFAULT_KERNEL,
        "CrIS footprint weighting: footprint (the FOV's radially symmetric response fitted over four annuli "
        "out to 0.64 deg, reported as its widths) or top-hat (the paper's 0.963 deg cone; biased by a real "
        "FOV's smooth response).",
    )
    cost: Cost = key(
        DEFAULT_COST,
        "The cost minimised over the perturbations: stdev (the paper's equation 8, "
        "STDEV(BT_VIIRS - BT_CrIS)) or regression (its residual after regression on BT_CrIS: a CrIS-VIIRS "
        "gain or bias does not move it).",
    )
    workers: int = key(2, "Threads of the compiled VIIRS preparation and collocation kernels.", 1, 64)
    min_coverage: float = key(
        0.97,
        "Share of a turned cone that VIIRS pixels must cover for the FOV to count (the swath's edges and "
        "gaps leave cones part empty).",
        0.5,
        1.0,
    )
    min_samples: int = key(
        30, "Fewest usable FOVs for a FOR's estimate (fewer: flagged few_samples), and for a day.", 3, 10**6
    )
    flat_contrast: float = key(
        0.03,
        "Least relative depth of a FOR's cost minimum; a shallower one is flagged flat (uniform scenes).",
        0.0,
        1.0,
    )
    max_sigma_urad: float = key(
        250.0, "Largest sigma of a trusted offset (urad, ~0.55 step); larger is flagged uncertain.", 1.0, 1e5
    )
    sigma_floor_urad: float | None = key(
        None,
        "Added in quadrature to the jackknife's sigma (urad), for an estimator error you know of. None: "
        "nothing where the configured kernel was used; a cone's estimate where the footprint is configured "
        "carries the day's cone-minus-footprint RMS.",
        0.0,
        1000.0,
    )
    uncertainty: bool = key(
        True, "Compute the jackknife's sigmas (off: offsets without sigmas, flags from the cost alone)."
    )
    parallax: bool = key(
        True,
        "Place each VIIRS pixel at the height its BT implies (colder than its clear-sky neighbourhood), "
        "with the day's height scale chosen by the cost: clouds with height seen by CrIS's FOV rows from "
        "another angle (the pixels rendered as each row sees them, collocated in the same pass; off: "
        "pixels at their GEO points).",
    )

    bands: Annotated[list[Band], Field(min_length=1)] = key(
        ["I5"],
        "The VIIRS bands CrIS is compared with radiometrically each day (I5, M13, M15, M16): per band and "
        "FOR, CrIS minus VIIRS over the FOVs uniform in VIIRS, on the assessed geolocation "
        "(cris_minus_viirs_k_<BAND>). The offsets are I5's; with M15 listed, the day is also assessed in "
        "M15 (d_alpha_urad_M15, ..., and M15 minus I5 with its paired sigma, flagged bands_differ beyond 3 "
        "sigmas).",
    )
    uniform_std_k: float = key(
        0.5,
        "A FOV is uniform in a band, and counts in its CrIS minus VIIRS, where the response-weighted "
        "standard deviation of its VIIRS pixels' BT (their noise included) is at most this, K.",
        0.01,
        10.0,
    )

    @property
    def step_rad(self) -> float:  # numpydoc ignore=RT01
        """The perturbation step in radians."""
        return self.step_urad * URAD

    @model_validator(mode="after")
    def _consistent(self) -> AssessmentConfig:
        spread = self.half_steps**2 * self.step_urad * URAD
        if spread > MAX_GRID_SPREAD_RAD:
            raise KeyProblem(
                "half_steps",
                f"{self.half_steps} with step_urad {self.step_urad:g}: half_steps^2 x step_urad = "
                f"{spread / URAD:.0f} urad is more than {MAX_GRID_SPREAD_RAD / URAD:.0f} (the widest grid of "
                "the compiled collocation)",
            )
        return self


def _paths(value: Any) -> Any:
    """One path or a list of paths."""
    if isinstance(value, str):
        return (value,)
    if not isinstance(value, list):
        raise ValueError(f"expected a list of paths, got {value!r}")
    return tuple(value)


class FingerprintConfig(Section):
    """The ``fingerprint`` section: the LOS fingerprint of the GEO files and the EP it points to."""

    granules: int = key(
        100, "GEO granules per day sampled (spread over the day) for the LOS fingerprint.", 1, 2000
    )
    threshold_urad: float = key(
        PROCESSING_CHANGE_URAD,
        "A FOR whose fingerprint angle moves more than this is a processing change.",
        0.1,
        10000,
    )
    ep_library: Annotated[tuple[FilePath, ...], BeforeValidator(_paths)] = key(
        (), "EP files or directories to identify the EP in use from; empty: the packaged real EPs."
    )
