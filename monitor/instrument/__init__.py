"""The instrument's models: the CrIS FOV's spatial response and the VIIRS I5 spectral response."""
