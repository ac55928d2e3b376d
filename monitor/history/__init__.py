"""What the service has recorded, as the alerts and the outputs read it: the store's rows as typed records,
the :class:`~monitor.history.records.History` interface the alerts program against, and the history of
known changes (calendar, granule metadata, recorded events)."""
