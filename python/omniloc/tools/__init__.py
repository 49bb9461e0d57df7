"""Output tools: the one markdown / HTML writer (markup) and its language for the papers (citations:
the bibliography, citations, abbreviations), picture compression (images) and the one plotting module
(plot: the only importer of matplotlib)."""
