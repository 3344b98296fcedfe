"""Exceptions raised by :mod:`harness.cosim.masters`."""

from __future__ import annotations

__all__ = ["SetupError", "LibcosimError"]


class SetupError(ValueError):
    """A run request the master cannot carry out as given.

    Raised before anything runs: an unknown FMU, instance or variable name (the
    message lists the names that exist), a value of the wrong type, a connection
    between incompatible variables, or a time grid the master cannot represent.
    """


class LibcosimError(RuntimeError):
    """libcosim or an FMU running in it reported an error, or the run did not finish.

    Attributes
    ----------
    fmu_log: the FMU log messages libcosim printed (status warning and worse), as
        ``"[status/category] message"`` strings, oldest first.
    console: everything the libcosim process printed (its log and any crash report).
    returncode: exit status of the libcosim process (negative: killed by that signal),
        or None when it was stopped after the timeout.
    """

    def __init__(self, message: str, *, fmu_log: tuple[str, ...] = (), console: str = "",
                 returncode: int | None = None):
        super().__init__(message)
        self.message = message
        self.fmu_log = tuple(fmu_log)
        self.console = console
        self.returncode = returncode

    def __str__(self) -> str:
        if not self.fmu_log:
            return self.message
        shown = self.fmu_log[-10:]
        skipped = f"\n  ... {len(self.fmu_log) - len(shown)} earlier lines" if len(self.fmu_log) > len(shown) else ""
        return self.message + "\nFMU log:" + skipped + "".join(
            "\n  " + line.replace("\n", "\n    ") for line in shown)
