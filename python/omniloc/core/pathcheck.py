"""Why a path the user gave a command cannot be used, in words, before anything is read or written
(the Python half of core/path_check.hpp, with the same words).

pathlib's is_dir() / exists() raise OSError for a name over NAME_MAX ("File name too long") instead
of answering, and open() on a FIFO blocks for ever: the commands ask here first, so a bad path
ends in exit 2 with the option and the reason, never a traceback or a hang.
"""
from __future__ import annotations

import errno
import os
import stat
from typing import Optional, Union

# What a command hands over: the option's text or a pathlib.Path made of it.
UserPath = Union[str, "os.PathLike[str]"]

# Writers put a temporary name beside their target (".NAME.XXXX.tmp"): the target's own name must
# leave this many characters of NAME_MAX for it (core/path_check.cpp uses the same room).
TEMPORARY_NAME_ROOM = 100
NAME_MAX = 255
PATH_MAX = 4096


def _kind(mode: int) -> str:
    if stat.S_ISREG(mode):
        return "a regular file"
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "neither a file nor a folder"


def _words(e: OSError) -> str:
    return e.strerror or os.strerror(e.errno or 0)


def _stat(path: str) -> Union[os.stat_result, str]:
    """os.stat's result, or the reason in words (a str) when it fails."""
    if path == "":
        return "an empty path"
    if "\0" in path:
        return "a NUL character in the path"
    try:
        return os.stat(path)
    except OSError as e:
        return _words(e)
    except ValueError as e:  # embedded NUL on some Python versions
        return str(e)


def why_not_readable_file(path: UserPath) -> Optional[str]:
    """Why `path` cannot be read as a regular file; None when it can."""
    st = _stat(os.fspath(path))
    if isinstance(st, str):
        return st
    if not stat.S_ISREG(st.st_mode):
        return f"{_kind(st.st_mode)}, not a regular file"
    if not os.access(path, os.R_OK):
        return os.strerror(errno.EACCES)
    return None


def why_not_readable_folder(path: UserPath) -> Optional[str]:
    """Why `path` cannot be read as a folder (listed and entered); None when it can."""
    st = _stat(os.fspath(path))
    if isinstance(st, str):
        return st
    if not stat.S_ISDIR(st.st_mode):
        return f"{_kind(st.st_mode)}, not a folder"
    if not os.access(path, os.R_OK | os.X_OK):
        return os.strerror(errno.EACCES)
    return None


def why_not_writable(path: UserPath, folder: bool) -> Optional[str]:
    """Why a regular file (`folder` False) or a folder cannot be written at `path`: another kind is
    there, a parent is not a folder or not writable, a name is over NAME_MAX or the path over
    PATH_MAX; None when nothing seen now stands in the way."""
    p = os.fspath(path)
    if p == "":
        return "an empty path"
    if "\0" in p:
        return "a NUL character in the path"
    too_long = os.strerror(errno.ENAMETOOLONG)
    if len(p) >= PATH_MAX:
        return f"{too_long} ({len(p)} characters; at most {PATH_MAX - 1})"
    p = os.path.normpath(p)
    for part in p.split(os.sep):
        if len(part.encode()) > NAME_MAX:
            return f"{too_long} (a name of {len(part.encode())} characters; at most {NAME_MAX})"
    last = os.path.basename(p)
    if len(last.encode()) + TEMPORARY_NAME_ROOM > NAME_MAX:
        return (f"{too_long} (its last name has {len(last.encode())} characters; at most {NAME_MAX - TEMPORARY_NAME_ROOM} "
                "leave room for the temporary name written beside it)")
    try:
        st = os.stat(p)
        if folder and not stat.S_ISDIR(st.st_mode):
            return f"{_kind(st.st_mode)}, not a folder"
        if not folder and not stat.S_ISREG(st.st_mode):
            return f"{_kind(st.st_mode)}, not a regular file"
        if folder:  # an existing folder is written into
            return None if os.access(p, os.W_OK | os.X_OK) else f"{os.strerror(errno.EACCES)} (cannot write into {p})"
    except FileNotFoundError:
        pass
    except OSError as e:
        return _words(e)
    parent = os.path.dirname(p)
    while parent and parent != os.sep:
        try:
            os.stat(parent)
            break
        except FileNotFoundError:
            if os.path.islink(parent):
                return f"{parent} is a symbolic link to nothing"
            parent = os.path.dirname(parent)
        except OSError as e:
            return _words(e)
    d = parent or "."
    if not os.path.isdir(d):
        return f"{d} is not a folder"
    if not os.access(d, os.W_OK | os.X_OK):
        return f"{os.strerror(errno.EACCES)} (cannot write into {d})"
    return None


def shown(path: UserPath) -> str:
    """`path` for a message: cut in the middle past 200 characters, so the reason stays readable."""
    s = os.fspath(path).replace("\0", "\\u0000")
    return s if len(s) <= 200 else f"{s[:100]}...({len(s)} characters)...{s[-60:]}"


class PathError(Exception):
    """A path the user gave that cannot be used: str(e) is "WHERE: got "PATH" (why), expected WHAT"."""


def _fail(where: str, path: UserPath, why: str, what: str) -> PathError:
    return PathError(f"{where}: got \"{shown(path)}\" ({why}), expected {what}")


def require_file(path: UserPath, where: str, what: str = "a readable file") -> None:
    why = why_not_readable_file(path)
    if why:
        raise _fail(where, path, why, what)


def require_folder(path: UserPath, where: str, what: str = "a readable folder") -> None:
    why = why_not_readable_folder(path)
    if why:
        raise _fail(where, path, why, what)


def require_writable(path: UserPath, where: str, folder: bool) -> None:
    why = why_not_writable(path, folder)
    if why:
        raise _fail(where, path, why, "a folder it can create or write into" if folder else "a file it can create or replace")
