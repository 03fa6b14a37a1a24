"""Figures of results (matplotlib): they draw, they never compute.  Units on every axis."""
