"""A landmark-selection metric of one's own: maximum parallax (docs/usage.md, "Your own method").

Over one observation interval t_s the lander moves v t_s; the line of sight to a landmark at
range rho, at the angle theta from the velocity, turns through about |v| t_s sin(theta) / rho
(rad). The larger that parallax, the better one new bearing fixes the landmark's depth, so this
metric picks the landmark of maximum parallax. The planner minimises: return minus the angle.
"""
import math


def parallax_score(c):
    """Minus the parallax (rad) of candidate ``c.p_L`` over one filter step (lower is better)."""
    d = c.p_L - c.r_L                          # lander -> candidate, {L}, m
    rho = math.sqrt(d @ d)
    speed = math.sqrt(c.v_L @ c.v_L)           # m/s
    if rho == 0.0 or speed == 0.0:
        return math.inf                        # no line of sight or no baseline: refused
    cos_t = (d @ c.v_L) / (rho * speed)
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    return -speed * c.t_s * sin_t / rho        # rad
