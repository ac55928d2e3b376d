"""The estimation: the cost, its sub-step minimum, the jackknife, the intercalibration."""
