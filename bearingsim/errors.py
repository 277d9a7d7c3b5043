"""User-facing errors: one line, names the key or file, exit code 2, no traceback."""


class UserError(Exception):
    """An error in what the user gave (scenario, override, path). The CLI prints it on one line."""

    exit_code = 2


def check_path(value, name: str, what: str):
    """``value`` when it is a path (a ``str`` or an ``os.PathLike``), else a one-line :class:`UserError`
    naming the argument ``name`` of the API and saying what it is the path of (``what``)."""
    import os

    if not isinstance(value, (str, os.PathLike)):
        raise UserError(f"{name}: expected the path of {what}, a str or a pathlib.Path (got {type(value).__name__})")
    return value


class SimulationUnstable(Exception):
    """A run diverged (non-finite state, penetration or energy growth). Never written as a result."""

    exit_code = 3


class PlausibilityWarning(UserWarning):
    """A run that is plausible but not clean (:func:`bearingsim.plausibility.check`): its result and
    archive stand, and the message says what to know about them."""


class UnreadKeyWarning(UserWarning):
    """A key the caller gave that the run does not read (:func:`bearingsim.scenario.unread_note`: a key its
    model or method does not use, or one its settings leave unread): a run with another value of it gives
    the same numbers. The message is the line ``bearingsim run`` prints as its note."""


class SlowLoopWarning(UserWarning):
    """The multibody model's compiled step loop cannot run with the installed pymunk: the plain loop
    runs instead (the same numbers, several times slower). Issued once per process."""
