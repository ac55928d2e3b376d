"""Alerting on the monitor's store: rules, change attribution, alert state, delivery channels.

The rules read what the service stored (per-FOR results, runs, events, granule metadata) and never the
science code; what they find is kept as alert state in the same SQLite file and sent through a
delivery queue, so a restart loses nothing and a channel that is down gets the message later.
"""
