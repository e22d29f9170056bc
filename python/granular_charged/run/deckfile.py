"""The input decks shipped as package data, and the variables a user may set in them.

A deck's settable variables are its ``variable NAME index DEFAULT`` lines (``-var NAME VALUE``
on LAMMPS's command line overrides exactly these); they are read from the deck that will run,
so a variable added to a deck is settable without a change here.
"""
from __future__ import annotations

import re
from functools import lru_cache
from importlib import resources

DECKS = ("in.deposition", "in.charged-after-formation")

# `variable NAME index VALUE ...`: the first value is the default (the rest of an index list
# would be the next values of a `next` loop, which the decks do not use)
_INDEX = re.compile(r"^\s*variable\s+(\S+)\s+index\s+(\S+)", re.M)


def deck_path(name: str):
    """A deck shipped as package data (a context manager yielding a real file path)."""
    if name not in DECKS:
        raise ValueError(f"unknown deck {name!r}; the package has {', '.join(DECKS)}")
    return resources.as_file(resources.files("granular_charged") / "decks" / name)


def parse_index_variables(text: str) -> dict[str, str]:
    """{name: default} of the ``variable NAME index DEFAULT`` lines of a deck's text (names
    starting with _ are the deck's own, not inputs)."""
    return {m.group(1): m.group(2) for m in _INDEX.finditer(text) if not m.group(1).startswith("_")}


@lru_cache(maxsize=None)
def deck_variables(name: str) -> dict[str, str]:
    """{name: default} of the variables a run can set in the packaged deck `name`."""
    with deck_path(name) as f:
        return parse_index_variables(f.read_text())
