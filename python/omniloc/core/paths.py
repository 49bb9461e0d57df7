"""Where the share root lies: the folder that holds results/reference, data and scenarios.

The package sits at <share>/python/omniloc, in a source tree (<share> = the checkout) and in the
installed package (<share> = /usr/share/omniloc) alike, so the share root is two folders above it.
"""
from __future__ import annotations



import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[3]
PAPERS = ROOT / "results" / "reference" / "papers.json"


