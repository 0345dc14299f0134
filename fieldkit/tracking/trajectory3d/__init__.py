"""3-D trajectories (x, y, z, t samples of a block on a DEM) -> ImpactTable.

Full-scale test sites publish the block's centre sampled at 100-200 Hz in the DEM's
coordinates, sometimes with its spin. One concept per module:

* :mod:`.samples` -- the trajectory CSV read strictly
  (:class:`.samples.Trajectory3D`);
* :mod:`.flights` -- the sampling noise and the ballistic flights (g fixed, no drag);
* :mod:`.surface` -- the local ground plane fitted over the block's footprint;
* :mod:`.contacts` -- where two consecutive flights meet: an impact on the ground, or
  a mid-air misfit (never an impact);
* :mod:`.impacts` -- the contacts as ImpactTable rows in the 3-D simulator's
  convention (:func:`fieldkit.model.results3d.impact_table3d`), with chainage and
  lateral deflection;
* :mod:`.synthetic` -- trajectories sampled from the 3-D simulator with exact truth.
"""
