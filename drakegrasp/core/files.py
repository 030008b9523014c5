"""Is a path a regular file?  Asked of ``stat`` alone, never by opening it.

Opening a named pipe blocks until a writer comes, and a device reads forever
or nothing; so every reader of a user's file (grasp files, datasets, scenes)
asks here first and refuses anything but a regular file by name, before it
opens it.
"""

from __future__ import annotations

import os
import stat

__all__ = ["MISSING", "not_a_file"]

MISSING = "does not exist"
"""What :func:`not_a_file` says of a path that names nothing."""

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def not_a_file(path: str | os.PathLike, noun: str = "a regular file") -> str:
    """Why ``path`` cannot be read as a regular file, or "" when it can.

    Symbolic links are followed (a link to a regular file is one; a link to
    nothing does not exist).

    Parameters
    ----------
    path : str or path-like
    noun : str, optional
        What was expected, for the message: "is a directory, not {noun}".

    Returns
    -------
    str
        "" for a regular file; else a phrase to follow the path's name:
        :data:`MISSING`, "is a named pipe (FIFO), not a regular file", "is a
        directory, not ...", "cannot be examined (Permission denied)".
    """
    try:
        mode = os.stat(path).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return MISSING
    except OSError as err:
        return f"cannot be examined ({err.strerror or err})"
    except ValueError:  # a NUL byte in the name
        return "is not a valid path"
    if stat.S_ISREG(mode):
        return ""
    kind = next((kind for test, kind in _KINDS if test(mode)), "a special file")
    return f"is {kind}, not {noun}"
