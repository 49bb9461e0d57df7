"""`omniloc export`: a run folder or a recording as an MCAP file of Foxglove messages (docs/viewer.md)."""
