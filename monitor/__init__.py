"""crisgeo-monitor: CrIS geolocation assessment against VIIRS I5 (Wang et al. 2017), run as a service.

The science lives in ``monitor.sdr`` (files), ``monitor.geometry`` (frames), ``monitor.spectral``,
``monitor.collocate``, ``monitor.assess`` and ``monitor.simulate``; it hands the service one typed
object, :class:`monitor.result.AssessmentResult`.
"""

__version__ = "0.1.0"
