"""Physical constants used throughout (thesis conventions)."""

#: Gravitational acceleration [m/s^2], as used by the thesis.
G = 9.81
