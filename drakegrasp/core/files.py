"""Is a path a regular file?  Asked of ``stat`` alone, never by opening it.

Opening a named pipe blocks until a writer comes, and a device reads forever
or nothing; so every reader of a user's file (grasp files, datasets, scenes)
asks here first and refuses anything but a regular file by name, before it
opens it.
"""

from __future__ import annotations

import os
import stat

__all__ = ["MISSING", "not_a_file", "unexaminable", "unlistable"]

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
    mode, why = _mode(path)
    if why:
        return why
    if mode is None:
        return MISSING
    if stat.S_ISREG(mode):
        return ""
    kind = next((kind for test, kind in _KINDS if test(mode)), "a special file")
    return f"is {kind}, not {noun}"


def unexaminable(path: str | os.PathLike) -> str:
    """Why nothing can be told of ``path`` (not even whether it exists), or "".

    pathlib's ``exists()``, ``is_dir()`` and ``is_file()`` raise
    ``PermissionError`` for a path inside a folder this process may not
    search; asked here first, such a path is refused by name.  A path that
    names nothing is examinable (it does not exist).

    Returns
    -------
    str
        "" when ``stat`` answers or finds nothing there; else a phrase to
        follow the path's name: "cannot be examined (Permission denied)",
        "is not a valid path".
    """
    return _mode(path)[1]


def unlistable(folder: str | os.PathLike) -> str:
    """Why the names in the directory ``folder`` cannot be read, or "".

    A folder this process may enter but not read lists as empty to
    ``glob`` (a grasp directory "holds []"), and raises ``PermissionError``
    from ``iterdir``; asked here first, it is refused by name.
    """
    try:
        os.scandir(folder).close()
    except OSError as err:
        return f"cannot be listed ({err.strerror or err})"
    return ""


def _mode(path) -> tuple[int | None, str]:
    """``path``'s ``st_mode`` (None: nothing there) and "", or None and why not."""
    try:
        return os.stat(path).st_mode, ""
    except (FileNotFoundError, NotADirectoryError):
        return None, ""
    except OSError as err:
        return None, f"cannot be examined ({err.strerror or err})"
    except ValueError:  # a NUL byte in the name
        return None, "is not a valid path"
