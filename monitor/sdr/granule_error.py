"""The one error type of the readers: it names the file, the field and what is wrong with it."""

from monitor.core.errors import DataError


class GranuleError(DataError):
    """A granule that cannot be used. ``str()`` reads ``FILE: FIELD: REASON``.

    Parameters
    ----------
    path : object
        The file.
    field : str
        The dataset or attribute.
    reason : str
        What is wrong with it.
    """

    def __init__(self, path: object, field: str, reason: str) -> None:
        self.path = str(path)
        self.field = field
        self.reason = reason
        super().__init__(f"{self.path}: {field}: {reason}")
