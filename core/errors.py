"""Errors raised for bad user input (files, fields, values).

The CLI turns an :class:`InputError` into one line on stderr and exit code 2; the app turns it
into a message box. The message must name the file, line or field and what was expected.
"""

from __future__ import annotations


class InputError(ValueError):
    """Bad user input: a malformed file, an unknown key, a value out of range.

    Parameters
    ----------
    message
        What is wrong and what was expected, naming the field (``"p_d must be in [0, 1], got
        p_d=1.5"``).
    source
        The file (and line, ``"scene.json:12"``) the input came from, if any.
    """

    def __init__(self, message: str, source: str | None = None) -> None:
        self.message = message
        self.source = source
        super().__init__(f"{source}: {message}" if source else message)
