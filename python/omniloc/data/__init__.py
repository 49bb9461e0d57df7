"""Readers of data sets that are not omniloc's own (the NuBot robots' calibration frames)."""
