"""Corridor scans: design energies, bounce heights and passing fractions at
stations along a road, railway or barrier line (:mod:`fieldkit.corridor.scan`)."""
