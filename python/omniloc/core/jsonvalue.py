"""Raw JSON as it enters the package, and the narrowing every reader applies to it.

JSON is what json.loads returns, spelled out: a reader takes a JSON value and returns a typed record
(a dataclass) or a plain value, and nothing past the reader sees an untyped value. The helpers
narrow one value to the type a format documents, and give None (or an empty container) where the
file holds something else, so a reader states its defaults in one place.

Numbers keep their JSON type: number() returns the int of an integer (a float only where the file
has one), so that text printed from it reads as the file does ("3", not "3.0").
"""
from __future__ import annotations

import json
import math
import pathlib
from typing import Optional, TypeGuard, Union

JSON = Union[None, bool, int, float, str, list["JSON"], dict[str, "JSON"]]
JSONObject = dict[str, JSON]


def obj(v: JSON) -> JSONObject:
    """v where it is an object, else an empty one."""
    return v if isinstance(v, dict) else {}


def lst(v: JSON) -> list[JSON]:
    """v where it is an array, else an empty one."""
    return v if isinstance(v, list) else []


def number(v: JSON) -> Optional[float]:
    """v where it is a JSON number (not a bool), else None; an integer stays an int."""
    return v if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def finite(v: object) -> TypeGuard[float]:
    """Whether v is a finite JSON number (not a bool)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def integer(v: JSON) -> Optional[int]:
    """v where it is a JSON integer (not a bool), else None."""
    return v if isinstance(v, int) and not isinstance(v, bool) else None


def text(v: JSON) -> Optional[str]:
    """v where it is a string, else None."""
    return v if isinstance(v, str) else None


def flag(v: JSON) -> Optional[bool]:
    """v where it is a bool, else None."""
    return v if isinstance(v, bool) else None


def numbers(v: JSON) -> Optional[list[float]]:
    """v where it is an array of numbers, else None."""
    if not isinstance(v, list):
        return None
    out = [number(x) for x in v]
    return [x for x in out if x is not None] if all(x is not None for x in out) else None


def parse(text_: str) -> JSON:
    """json.loads, typed: the one place a JSON document becomes a JSON value."""
    value: JSON = json.loads(text_)
    return value


def load_file(path: pathlib.Path) -> JSON:
    """The JSON document of a file (OSError and ValueError as json.loads raises them)."""
    return parse(path.read_text())
