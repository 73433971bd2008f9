"""Figures of a build, one module per subject; matplotlib (Agg) only in here."""
