"""Exception types for expected user mistakes (the CLI prints them without a traceback)."""


class SamvgError(Exception):
    """Base class of every error that the command line reports as a plain message."""


class InputError(SamvgError, ValueError):
    """Bad user input: an unreadable or corrupt file, an unsupported image mode, NaN coordinates."""


class WeightsError(SamvgError):
    """Model weights that cannot be found, downloaded, verified or loaded."""
