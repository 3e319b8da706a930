"""Planning time by replay (paper B sec. 3, Fig. 7 and the time reduction of
Table 3; SPEC B.4).

Description
-----------
The descent (``opnav.landing.descent.run_descent``) records, per planning
call, everything ``planner.plan`` takes: the filter step (the truth pose, hence
the camera's detected landmarks, follows from the scenario), the estimate
``PlanState(r, v, a, R_LtoB, P)``, the excluded current landmark and the state
of the run's picker stream (:data:`RECORD_KEYS`). Timing is then done apart
from the filter's own work.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RECORD_KEYS", "record_plan_inputs", "stack_plan_inputs", "rng_words", "rng_from_words"]

#: per planning call: filter step index, estimate r (3), v (3), a (3), R_LtoB (3, 3),
#: covariance P (12, 12), excluded landmark (-1: none), picker stream state (6 words)
RECORD_KEYS = ("plan_step", "plan_r", "plan_v", "plan_a", "plan_R", "plan_P", "plan_exclude",
               "plan_rng")
_SHAPES = {"plan_step": (), "plan_r": (3,), "plan_v": (3,), "plan_a": (3,), "plan_R": (3, 3),
           "plan_P": (12, 12), "plan_exclude": (), "plan_rng": (6,)}
_DTYPES = {"plan_step": np.int64, "plan_exclude": np.int64, "plan_rng": np.uint64}
_MASK64 = (1 << 64) - 1


def rng_words(rng: np.random.Generator | None) -> np.ndarray:
    """The state of a PCG64 generator as 6 uint64 words (state hi/lo, inc
    hi/lo, has_uint32, uinteger); zeros for no generator."""
    if rng is None:
        return np.zeros(6, np.uint64)
    s = rng.bit_generator.state
    if s["bit_generator"] != "PCG64":
        raise ValueError(f"rng_words: PCG64 expected, got {s['bit_generator']}")
    st, inc = int(s["state"]["state"]), int(s["state"]["inc"])
    return np.array([st >> 64, st & _MASK64, inc >> 64, inc & _MASK64, int(s["has_uint32"]),
                     int(s["uinteger"])], np.uint64)


def rng_from_words(words) -> np.random.Generator:
    """Inverse of :func:`rng_words`: a generator in exactly that state."""
    w = [int(x) for x in np.asarray(words, np.uint64)]
    g = np.random.Generator(np.random.PCG64())
    g.bit_generator.state = {"bit_generator": "PCG64",
                             "state": {"state": (w[0] << 64) | w[1], "inc": (w[2] << 64) | w[3]},
                             "has_uint32": w[4], "uinteger": w[5]}
    return g


def record_plan_inputs(rec: dict, step: int, r, v, a, R_LtoB, P, exclude: int,
                       rng: np.random.Generator | None) -> None:
    """Append one planning call's inputs to ``rec`` (lists keyed by
    :data:`RECORD_KEYS`); call it just before ``planner.plan``."""
    for key, val in zip(RECORD_KEYS, (int(step), r, v, a, R_LtoB, P, int(exclude), rng_words(rng))):
        rec[key].append(np.array(val, _DTYPES.get(key, float), copy=True))


def stack_plan_inputs(rec: dict) -> dict:
    """The recorded lists as arrays (calls first), empty arrays of the right shape if none."""
    return {k: (np.stack(rec[k]) if rec[k] else np.zeros((0,) + _SHAPES[k], _DTYPES.get(k, float)))
            for k in RECORD_KEYS}
