"""The configuration: the model (every key once), the file, the generated reference."""
