"""Virtual field campaigns: simulated rocks surveyed as a geologist would (issue 18).

A model's rocks are simulated with any hidden effects; each rock's path is then
*surveyed*: scars only where an impact marks the ground, neighbouring scars merged,
GNSS/rangefinder error on every point, tree strikes where the path crosses trees, and
no launch angle observed. The result is the raw field files ``fieldkit reduce``
reads, with the truth beside them (:mod:`fieldkit.campaign.virtual`).
"""
