"""Straight-line tracking over a tire population: tire slots and files, statistics, the mounting plan."""
