"""Exception types for expected user mistakes (the CLI prints them without a traceback)."""


class SamvgError(Exception):
    """Base class of every error that the command line reports as a plain message."""


class InputError(SamvgError, ValueError):
    """Bad user input: an unreadable or corrupt file, an unsupported image mode, NaN coordinates."""


class OutputError(SamvgError, OSError):
    """An output that cannot be written: a folder where a file should go, a missing or read-only
    folder, the input itself, or a write that failed (a full disk). An `OSError` too, as the
    failed write was before."""


class WeightsError(SamvgError):
    """Model weights that cannot be found, downloaded, verified or loaded."""


class WeightsNotFoundError(WeightsError):
    """No weight file anywhere (nothing named, none in the cache) and no download worked; the
    only weights problem that may be met with a fallback (LPIPS off)."""
