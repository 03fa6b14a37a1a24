"""Linear analysis of the model: modes, steady state, geometry, exact discretization,
time responses, modal superposition, the state-space form and the yaw-plane measures."""
