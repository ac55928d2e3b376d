"""The project's one base for errors in the data it is given: callers catch this, not ValueError (which
would also swallow programming errors such as shape bugs)."""


class DataError(ValueError):
    """Input data that cannot be used; the message names the file or item, the field and the value."""


class AssessmentError(DataError):
    """The granules given leave too little to assess (a table of NaN is never returned instead)."""
