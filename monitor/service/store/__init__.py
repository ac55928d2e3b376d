"""Stores: the embedded SQLite store (its file, schema, ledger, results, outbox and alert state) and the
time-series publishers."""
