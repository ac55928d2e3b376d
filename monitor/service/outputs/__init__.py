"""What the service gives its readers, each derived from the store and the typed result: results as data
(NetCDF, CSV, xarray: :mod:`.export`), the time-series lines and their writers (:mod:`.timeseries`),
``/metrics`` (:mod:`.metrics`) and the HTML trend report (:mod:`.report`)."""
