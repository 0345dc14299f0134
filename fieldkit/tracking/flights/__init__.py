"""Track -> ImpactTable: flight segmentation, ballistic fits, end trimming, contacts,
impacts and net contacts."""
