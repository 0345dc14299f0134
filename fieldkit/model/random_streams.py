"""Counter-based random numbers: every draw a pure function of (key, counter, slot).

Each rock has a 64-bit ``key`` (drawn once from the run's numpy Generator). Inside the
kernel a random number is ``hash(key, counter, slot)`` with the splitmix64 finaliser:
``counter`` is the impact number, ``slot`` a fixed number per use (:data:`SLOTS`).
So threads may run rocks in any order, and switching an effect on or off never moves
another effect's numbers (common random numbers): neutral parameters reproduce the
base model exactly, and fits compare models on the same draws.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Fixed slots per impact counter. Normals use uniforms 2*slot and 2*slot+1.
SLOTS = {
    "e_n": 0,
    "e_t": 1,
    "roughness": 2,
    "friction": 1000,  # + segment entry number within one slide
    "tree": 100,  # + tree index (uniform)
}
SLOT_E_N, SLOT_E_T, SLOT_ROUGHNESS, SLOT_TREE, SLOT_FRICTION = 0, 1, 2, 100, 1000

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_S30, _S27, _S31, _S11 = np.uint64(30), np.uint64(27), np.uint64(31), np.uint64(11)
_SLOT_BITS = np.uint64(20)


@njit(cache=True)
def mix64(z):
    """splitmix64 finaliser of a uint64."""
    z = (z ^ (z >> _S30)) * _M1
    z = (z ^ (z >> _S27)) * _M2
    return z ^ (z >> _S31)


@njit(cache=True)
def uniform(key, counter, slot):
    """Uniform in (0, 1) from (key, counter, slot); never 0 or 1."""
    c = (np.uint64(counter) << _SLOT_BITS) + np.uint64(slot)
    h = mix64(key ^ mix64(c * _GOLDEN + _GOLDEN))
    return (np.float64(h >> _S11) + 0.5) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def normal(key, counter, slot):
    """Standard normal from (key, counter, slot), Box-Muller on two uniforms."""
    u1 = uniform(key, counter, 2 * slot)
    u2 = uniform(key, counter, 2 * slot + 1)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)
