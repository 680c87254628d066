"""The exceptions of ranger_can: every error carries the library's own message."""


class RangerError(Exception):
    """An error of libranger_can: `args[0]` is the library's message, `code` its kind
    ("invalid_argument", "not_finite", "interface_down", ...)."""

    def __init__(self, message, code="error"):
        super().__init__(message)
        self.message = message
        self.code = code

    def __str__(self):
        return self.message


class RequestFailed(RangerError):
    """A request the driver (or the chassis) refused or failed; `outcome` says what became of it."""

    def __init__(self, message, outcome=None):
        super().__init__(message, "request_failed")
        self.outcome = outcome


class RequestTimeout(RangerError, TimeoutError):
    """Nothing answered in time (a request, or wait_ready)."""

    def __init__(self, message, outcome=None):
        super().__init__(message, "timeout")
        self.outcome = outcome
