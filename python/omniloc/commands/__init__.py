"""Thin command modules: `omniloc <command>` runs `python3 -m omniloc.commands.<command>`."""
