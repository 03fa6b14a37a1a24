"""The nonlinear planar model (docs/nonlinear.md): any angle, saturating tires."""
