"""One eigenvalue routine everywhere, the accurate one (issue 22): on long chains at low
speed the eigenvalues of ``lcv eig``/``modes()`` and ``eigenvalues()`` equal a 50-digit
mpmath computation to within their condition numbers."""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg

from lcvreport.analysis.modes import eigenvalues, modes
from lcvreport.model.yaw_plane.equations import system_coefficients

from helpers import random_vehicle

EPS = np.finfo(float).eps


@pytest.mark.parametrize("seed", [0, 1])
def test_eigenvalues_of_an_18_unit_road_train_equal_mpmath_within_their_condition(seed):
    v = random_vehicle(18, np.random.default_rng(seed))
    u = 2.5                                                  # 9 km/h: the widest spread of time scales
    co = system_coefficients(v)
    M, S = co.M(u), co.S(u, 1.0)
    mp.mp.dps = 50
    A = mp.inverse(mp.matrix(M.tolist())) * mp.matrix(S.tolist())
    ref = np.array([complex(e) for e in mp.eig(A, left=False, right=False)])
    # condition of each eigenvalue of A = M^-1 S: 1/|y^H x| with unit left and right vectors
    A64 = np.linalg.solve(M, S)
    lam, Y, X = scipy.linalg.eig(A64, left=True, right=True)
    kappa = 1.0 / np.abs(np.einsum("ij,ij->j", Y.conj(), X))
    bound = {complex(lam[i]): 100 * kappa[i] * EPS * np.linalg.norm(A64, 2) for i in range(lam.size)}
    for name, got in (("modes", modes(v, u).eigenvalues), ("eigenvalues", eigenvalues(v, u))):
        for r in ref:
            nearest = got[np.argmin(np.abs(got - r))]
            tol = bound[min(bound, key=lambda z: abs(z - r))]
            assert abs(nearest - r) <= tol, (name, r, nearest, tol)
    assert np.isclose(modes(v, u).max_real, ref.real.max(), rtol=1e-6, atol=0)
