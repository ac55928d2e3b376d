"""The service configuration, declared once: one model per section (a module each), alerts included.

Each key is a typed field with its default, its range (``ge``/``le``, in the unit its name ends in) and its
meaning (the field's description). The same model validates a file (:mod:`monitor.config.file`: reading,
one-line errors, printing, the JSON Schema), the command line's options, and writes the reference
(``docs/configuration.md``, :mod:`monitor.config.reference`). Adding a key is adding a field.

Every error names the key and the problem in one line (``ConfigError: store.publish[0].url: missing``).
Keys whose value is a secret end in ``_env`` and hold the *name* of an environment variable, never the
secret. Relative paths are relative to the file.
"""
