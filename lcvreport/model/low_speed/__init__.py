"""The low-speed kinematic model: pull points and the heading law of every unit along a path."""
