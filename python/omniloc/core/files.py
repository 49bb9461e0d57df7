"""Reading the files of the seam: the input error that names a file, its line and what was expected,
and the one loop over a file of JSON lines (events.jsonl, view.jsonl, a recording's frames,
the history's .jsonl files).

A strict reader raises InputFileError before anything is drawn or written (the run viewer); a
lenient one (the report, which must go on past a malformed run) asks json_lines to skip what it
cannot read.
"""
from __future__ import annotations

import csv
import errno
import json
import os
import pathlib
from typing import Iterator, Optional

from omniloc.core import pathcheck
from omniloc.core.jsonvalue import JSON, JSONObject


class InputFileError(Exception):
    """Bad input: `path` (and `line`, 1-based) and what was expected. str() is one line."""

    def __init__(self, path: pathlib.Path | str, what: str, line: Optional[int] = None) -> None:
        self.path = str(path)
        self.line = line
        self.what = what
        where = self.path if line is None else f"{self.path} line {line}"
        super().__init__(f"{where}: {what}")


def check_file(path: pathlib.Path, what: str) -> None:
    """InputFileError unless `path` is a readable regular file: asked before reading, as reading a
    FIFO blocks for ever. "missing" is kept for a file that is not there (the common case)."""
    why = pathcheck.why_not_readable_file(path)
    if why == os.strerror(errno.ENOENT):
        raise InputFileError(path, f"missing: expected {what}")
    if why:
        raise InputFileError(path, f"{why}: expected {what}")


def read_text(path: pathlib.Path, what: str) -> str:
    """The file's text (UTF-8); InputFileError when it is missing, not a readable regular file or
    unreadable."""
    check_file(path, what)
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise InputFileError(path, f"unreadable ({e.__class__.__name__}): expected {what}") from None


def read_json_object(path: pathlib.Path, what: str, required: bool) -> JSONObject:
    """A file holding one JSON object (summary.json, config.json, field.json); {} where it is absent
    and not `required`; InputFileError where it is missing, unreadable or not an object."""
    if not path.exists() and not required:
        return {}
    try:
        v: JSON = json.loads(read_text(path, what))
    except json.JSONDecodeError as err:
        raise InputFileError(path, f"expected {what} ({err.msg})", err.lineno) from None
    if not isinstance(v, dict):
        raise InputFileError(path, f"expected {what}")
    return v


def json_lines(text: str, path: pathlib.Path, expected: str = "one JSON object per line", skip_blank: bool = True,
               skip_bad: bool = False, column: bool = False) -> Iterator[tuple[int, JSON]]:
    """(line number, value) of each line of `text`, a file of JSON lines read from `path`. A line that
    is not JSON raises InputFileError "expected <expected> (<the parser's message>[ at column N])",
    or with skip_bad is left out; blank lines are left out unless skip_blank is False (then they
    are lines that are not JSON)."""
    for n, line in enumerate(text.splitlines(), 1):
        if skip_blank and not line.strip():
            continue
        try:
            value: JSON = json.loads(line)
        except json.JSONDecodeError as err:
            if skip_bad:
                continue
            raise InputFileError(path, f"expected {expected} ({err.msg}" + (f" at column {err.colno})" if column else ")"), n) from None
        yield n, value


def read_json_lines(path: pathlib.Path) -> list[JSON]:
    """Every line of a file of JSON lines that parses; [] without the file. For files appended to by
    scripts (results/history): a line cut by an interrupted append does not hide the others."""
    if not path.exists():
        return []
    return [v for _, v in json_lines(path.read_text(), path, skip_bad=True)]


def read_csv(path: pathlib.Path) -> list[dict[str, str]]:
    """The rows of a CSV file with a header (frames.csv, timing.csv, runs.csv, an experiment's
    table) as {column: text}; [] without the file."""
    if not path.exists():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))
