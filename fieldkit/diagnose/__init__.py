"""Diagnose: compare model and measurement, find where it fails and what is missing."""
