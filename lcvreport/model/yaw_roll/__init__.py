"""The linear yaw-roll model (docs/roll.md): roll data, equations, the static rollover threshold."""
