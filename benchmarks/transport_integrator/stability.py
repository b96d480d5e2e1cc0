#!/usr/bin/env python3
"""Linear stability limits of the explicit SSP Runge-Kutta methods with the
upwind DG transport, by Fourier analysis of 1D advection on a uniform mesh.

Usage: python3 benchmarks/transport_integrator/stability.py

For DG degree k (Legendre basis, upwind flux) the semi-discrete operator of
u_t + u_x = 0 has, for each wave number theta, k + 1 eigenvalues lambda in
units of |u| / h. A method with stability polynomial R is stable for
dt |u| / h <= nu if |R(nu lambda)| <= 1 for all of them; nu is found by
bisection. Printed also in the units of 'Solid/Transport CFL', dt |u| (2k+1) / h.
"""
import numpy as np
from numpy.polynomial import legendre


def eigenvalues(k, thetas):
    n = k + 1
    P = [legendre.Legendre.basis(i) for i in range(n)]
    x, w = legendre.leggauss(n + 2)
    M = np.diag([2. / (2 * i + 1) for i in range(n)])
    A = np.zeros((n, n))  # the cell's own: volume term and outflow at +1
    B = np.zeros((n, n))  # inflow at -1 from the upwind neighbour's +1
    for j in range(n):
        for i in range(n):
            A[j, i] = np.sum(w * P[i](x) * P[j].deriv()(x)) - P[i](1.) * P[j](1.)
            B[j, i] = P[i](1.) * P[j](-1.)
    lam = [np.linalg.eigvals(np.linalg.solve(M, A + B * np.exp(-1j * t))) * 2. for t in thetas]
    return np.concatenate(lam)  # reference cell of length 2: x2 for units of |u| / h


METHODS = {
    "SSP-RK2": lambda z: 1 + z + z**2 / 2,
    "SSP-RK3": lambda z: 1 + z + z**2 / 2 + z**3 / 6,
    # y1 = y0 + h/2 L y0, y2 = y1 + h/2 L y1, y3 = y0/3 + 2/3 (y2 + h/2 L y2)
    "SSP-RK(3,2)": lambda z: 1. / 3. + 2. / 3. * (1 + z / 2)**3,
    # a candidate, not in the solver (session 33): Spiteri & Ruuth's
    # four-stage third-order method, y1 = y0 + h/2 L y0, y2 = y1 + h/2 L y1,
    # y3 = 2/3 y0 + 1/3 (y2 + h/2 L y2), y4 = y3 + h/2 L y3
    "SSP-RK(4,3)": lambda z: (2. / 3. + 1. / 3. * (1 + z / 2)**3) * (1 + z / 2),
}

thetas = np.linspace(0., 2. * np.pi, 721)
print(f"{'k':>2s} {'method':12s} {'dt|u|/h':>8s} {'dt|u|(2k+1)/h':>14s} {'per stage':>10s}")
for k in (1, 2):
    lam = eigenvalues(k, thetas)
    for name, R in METHODS.items():
        lo, hi = 0., 5.
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if np.max(np.abs(R(mid * lam))) <= 1. + 1e-12:
                lo = mid
            else:
                hi = mid
        stages = {"SSP-RK2": 2, "SSP-RK(4,3)": 4}.get(name, 3)
        print(f"{k:2d} {name:12s} {lo:8.4f} {lo * (2 * k + 1):14.4f} {lo / stages:10.4f}")
