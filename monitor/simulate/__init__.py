"""A simulator of CrIS and VIIRS I5 granules in the exact JPSS layout, with injected CrIS LOS errors.

Radiances come from the true lines of sight over a synthetic inhomogeneous Earth (clouds over ocean,
coastlines); the CrIS GEO is computed from the erroneous ones. The CrIS truth is the scene integrated
over the true FOV cone, independently of the VIIRS pixel grid (no "inverse crime", docs/science.md).
"""

CIRRUS_BASE_M = 7000.0  # a cloud met above this is cirrus: SimulationSpec.cloud_emissivity; below, opaque
LAYOUTS = ("contiguous", "gzip")  # of every dataset: uncompressed IDPS files; one gzip chunk per dataset
