"""omniloc's results half: reads run folders, sweep folders and aggregates (docs/results.md) and turns
them into judgements: statistics, compare, gate, paper tables and claims, the report, the run viewer.

The C++ half writes the run folder; this package only reads it (docs/architecture.md).
"""
