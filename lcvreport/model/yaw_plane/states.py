"""The yaw-plane model's state vector: its names and the letters of the joints.

The states of an N-unit chain are ``v1`` (unit 1's lateral velocity [m/s]), ``r1 .. rN``
(yaw rates [rad/s]) and the N-1 articulation angles ``thetaA, thetaB, ...`` [rad], joints
lettered A, B, C ... from the front as in thesis Table 3-2 (see ``docs/model.md``).

Examples
--------
>>> state_names(3)
('v1', 'r1', 'r2', 'r3', 'thetaA', 'thetaB')
>>> joint_letter(0), joint_letter(26)
('A', 'AA')
"""
from __future__ import annotations




def joint_letter(k: int) -> str:
    """Letter of joint ``k`` (0-based: A, B, ..., Z, AA, AB, ...), as in thesis Table 3-2."""
    if k < 0:
        raise ValueError("joint index must be >= 0")
    letters = ""
    k += 1
    while k:
        k, rem = divmod(k - 1, 26)
        letters = chr(ord("A") + rem) + letters
    return letters


def state_names(n_units: int) -> tuple[str, ...]:
    """Names of the state ``x = [v1, r1..rN, thetaA..]`` of an N-unit chain."""
    return ("v1",) + tuple(f"r{i + 1}" for i in range(n_units)) + tuple(
        f"theta{joint_letter(k)}" for k in range(n_units - 1))
