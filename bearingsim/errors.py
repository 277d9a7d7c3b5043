"""User-facing errors: one line, names the key or file, exit code 2, no traceback."""


class UserError(Exception):
    """An error in what the user gave (scenario, override, path). The CLI prints it on one line."""

    exit_code = 2


class SimulationUnstable(Exception):
    """A run diverged (non-finite state, penetration or energy growth). Never written as a result."""

    exit_code = 3
