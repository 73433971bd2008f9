"""Plane geometry shared by the writers and the solids (no file formats, no engines)."""
