"""Gears: cutter envelopes (teeth), profiles, non-circular pairs, trains, meshing check."""
