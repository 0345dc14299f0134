"""Readers and writers at the edge of fieldkit: field formats in, tables out.

One module per format. Every reader converts units and renames columns to the contract
names once, here, and raises :class:`fieldkit.errors.InputFileError` naming the file and
the row or point on bad input.
"""
