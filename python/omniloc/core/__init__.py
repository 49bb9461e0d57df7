"""The results' core: one reader per format of the seam (run folders, sweep folders and aggregates,
events.jsonl, view.jsonl, recordings), each giving typed records from raw JSON; pairing runs with
published rows by key, statistics for few seeds, and how every tool names a metric. No plotting, no
command line: nothing here imports matplotlib, not even indirectly
(python/tests/test_core_without_matplotlib.py), nor anything of the package outside core/
(python/tests/test_layers.py)."""
