"""The results' core: reading run and sweep folders, pairing runs with published rows by key,
statistics for few seeds, and how every tool names a metric. No plotting, no command line: nothing
here imports matplotlib, not even indirectly (python/tests/test_core_without_matplotlib.py)."""
