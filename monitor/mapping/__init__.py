"""From assessment to mapping angles (paper section 4): the LOS fingerprint of GEO files and the EP it
matches, the per-FOR LOS residual table, the mapping-angle optimiser and regeolocation. The EP files
themselves are a format: :mod:`monitor.sdr.engpkt`."""
