"""The service: the daily pipeline, sources, stores, the report, HTTP, the daemon."""
