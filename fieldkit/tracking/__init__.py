"""High-speed video and track exports -> Track -> flights and impacts (ImpactTable)."""
