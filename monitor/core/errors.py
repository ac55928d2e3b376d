"""The project's one base for errors in the data it is given: callers catch this, not ValueError (which
would also swallow programming errors such as shape bugs)."""


class DataError(ValueError):
    """Input data that cannot be used; the message names the file or item, the field and the value."""


class StopRequested(Exception):  # noqa: N818 - a request, not an error
    """A stop was asked for (SIGTERM, SIGINT) between two steps; the caller records an interruption."""


class AssessmentError(DataError):
    """The granules given leave too little to assess (a table of NaN is never returned instead)."""
