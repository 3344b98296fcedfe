"""The one exception type raised by :mod:`harness.ground.records`."""

from __future__ import annotations

__all__ = ["RecordError"]


class RecordError(ValueError):
    """A ground-motion record cannot be read, interpreted or processed.

    The message always names what is wrong (with the offending value where
    there is one) and what to do about it. It subclasses :class:`ValueError`
    so that generic callers that only catch ``ValueError`` still see it.
    """
