"""Tracking in two stages: ``video`` (pixels -> Track) and ``flights`` (Track ->
ImpactTable)."""
