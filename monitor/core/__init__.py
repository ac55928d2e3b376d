"""The shared ground floor: instrument constants, errors, the vocabulary, the typed results and records,
tables as data, the satellite table, the history of changes."""
