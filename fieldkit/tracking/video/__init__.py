"""Video -> Track: pixels to world positions and spin (reader, background, detection,
calibration, marker spin)."""
