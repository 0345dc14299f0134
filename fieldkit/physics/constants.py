"""Physical constants used throughout (thesis conventions)."""

#: Gravitational acceleration [m/s^2], as used by the thesis.
G = 9.81

# Sizes beyond which a number is a typo or a unit slip, not a rockfall (one set for the
# command line's options and the ImpactTable reader; each use states the reason).

#: Largest rockfall speed [m/s]: free fall from 500 m reaches 99 m/s.
MAX_SPEED_MPS = 100.0
#: Smallest and largest rock [kg]: below a gram it is sand; 10,000 t (3,700 m3) is a
#: rock avalanche, not a rockfall.
MIN_MASS_KG, MAX_MASS_KG = 1e-3, 1e7
#: Smallest and largest contact radius or radius of gyration [m]: a millimetre (k^2 of
#: 1e-300 m underflows to zero); rockfall blocks are at most a few metres across.
MIN_LENGTH_M, MAX_LENGTH_M = 1e-3, 10.0
