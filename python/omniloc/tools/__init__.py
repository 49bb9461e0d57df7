"""Output tools: the one markdown / HTML writer (markup), picture compression (images) and the one
plotting module (plot: the only importer of matplotlib)."""
