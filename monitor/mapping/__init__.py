"""From assessment to mapping angles: EP files, the optimiser and regeolocation (paper section 4)."""
