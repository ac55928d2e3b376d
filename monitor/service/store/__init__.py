"""Stores: the embedded SQLite store (runs, results, granules, outbox) and time-series publishers."""
