"""Test helpers: a hypothesis strategy for random A-trains."""
from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from lcvreport.vehicle import Axle, Train, Unit


def random_train(n_units: int, rng: np.random.Generator, cm: bool = True) -> Train:
    """A physically plausible random A-train of ``n_units`` units (thesis units)."""
    units = []
    for k in range(n_units):
        i = k + 1
        if k == 0:
            axles = [Axle("11", 1, rng.uniform(60, 120), rng.uniform(8e3, 14e3), 2, rng.uniform(4e4, 7e4),
                          rng.uniform(5e4, 1.5e5) if cm else 0.0, 0.0, dual=False, steer=True),
                     Axle("12", 1, -rng.uniform(40, 100), rng.uniform(1.5e4, 2.2e4), 4, rng.uniform(6e4, 1.2e5),
                          rng.uniform(1e5, 2.6e5) if cm else 0.0, rng.uniform(1e5, 2.2e5) if cm else 0.0, dual=True)]
            front, mass, inertia = 0.0, rng.uniform(40, 100), rng.uniform(1e5, 4e5)
        elif k % 2 == 1:  # semitrailer
            axles = [Axle(f"{i}1", i, -rng.uniform(60, 160), rng.uniform(4e3, 2.2e4), 4, rng.uniform(3e4, 1.2e5),
                          rng.uniform(3e4, 2.6e5) if cm else 0.0, rng.uniform(5e4, 2.2e5) if cm else 0.0, dual=True)]
            front, mass, inertia = rng.uniform(60, 140), rng.uniform(20, 130), rng.uniform(3e5, 1.3e6)
        else:  # converter dolly
            axles = [Axle(f"{i}1", i, -rng.uniform(0, 10), rng.uniform(8e3, 2.2e4), 4, rng.uniform(5e4, 1.2e5),
                          rng.uniform(6e4, 2.6e5) if cm else 0.0, rng.uniform(8e4, 2.2e5) if cm else 0.0, dual=True)]
            front, mass, inertia = rng.uniform(60, 90), rng.uniform(8, 12), rng.uniform(2e3, 3e3)
        rear = rng.uniform(60, 200) if k % 2 == 1 or k == 0 else rng.uniform(0, 5)
        units.append(Unit(i, f"u{i}", "tractor" if k == 0 else "trailer" if k % 2 else "dolly",
                          mass, inertia, front, rear, tuple(axles)))
    return Train(f"random{n_units}", tuple(units), dual_spacing_in=rng.uniform(10, 14))


@st.composite
def trains(draw, min_units: int = 1, max_units: int = 6, cm: bool = True):
    n = draw(st.integers(min_units, max_units))
    seed = draw(st.integers(0, 2**32 - 1))
    return random_train(n, np.random.default_rng(seed), cm=cm)


speeds = st.floats(min_value=100.0, max_value=1400.0, allow_nan=False)  # in/s (about 6..80 mph)
