"""CrIS FOVs mapped onto VIIRS (I5, M13, M15, M16): the VIIRS scene inside every FOV and CrIS in each
band, as a product (``crisgeo map``). Not :mod:`monitor.mapping`, which derives CrIS mapping angles."""

from monitor.matchup.product import VARIABLES, Matchup
from monitor.matchup.run import MapCost, map_granules, map_plan

__all__ = ["VARIABLES", "MapCost", "Matchup", "map_granules", "map_plan"]
