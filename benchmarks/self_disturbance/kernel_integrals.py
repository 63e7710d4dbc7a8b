#!/usr/bin/python3
"""The self-mobility constants of source/coupling/self_disturbance.cc.

A grain's drag f, spread over the fluid with a kernel g and felt through the
same kernel, disturbs the velocity it feels by u_self = K f, with (3D, steady
Stokes, unbounded fluid of viscosity mu)

    K mu = (2/3) int |g^(k)|^2 / k^2 d^3k / (2 pi)^3

(2/3 = the mean of 1 - k_z^2/k^2; exact for kernels with the symmetry of the
cube). With 1/(k^2 (1 + l^2 k^2)^2) = int_0^inf exp(-t k^2) F(t) dt,
F(t) = 1 - exp(-t/l^2) (1 + t/l^2) (F = 1 without filter), the integral
separates into one-dimensional ones:

    K mu h = (2/3) int_0^inf F(t) I(t)^3 dt,  I(t) = int S(k) exp(-t k^2) dk/2pi

with h = 1, S(k) = sinc^2(k/2) for the cell's indicator (Drag distribution =
cell: spread evenly over the cell, felt as the cell mean) and sinc^4(k/2) for
the Q1 hat (filtered: spread through the Q1 shape functions, then the
Helmholtz filter of length l). Prints the constants and the table the code
interpolates.

Build-up: in a fluid at rest that feels a constant force from t = 0
(unsteady Stokes), the same integral runs over t < nu t' only,

    K(t') / K = int_0^{nu t'} F(t) I(t)^3 dt / int_0^inf F(t) I(t)^3 dt,

and the time at which it reaches 1 - 1/e is the build-up time t_K of
source/coupling/self_disturbance.cc (the tail beyond it is slow, ~ t'^-1/2).
"""
import numpy as np

k = np.linspace(-400.0, 400.0, 800001)
dk = k[1] - k[0]
t = np.logspace(-7, 6, 1300)


def I(power):
    S = np.sinc(k / (2 * np.pi)) ** power  # np.sinc(x) = sin(pi x)/(pi x)
    return np.array([np.sum(S * np.exp(-ti * k * k)) * dk / (2 * np.pi) for ti in t])


def integrate(y):
    return np.trapz(y, t)


I_cell, I_hat = I(2), I(4)
print("cell: K mu h = %.5f" % ((2 / 3) * integrate(I_cell ** 3)))
for l in [0.0, 0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0]:
    F = np.ones_like(t) if l == 0 else 1 - np.exp(-t / l**2) * (1 + t / l**2)
    c = (2 / 3) * integrate(F * I_hat ** 3)
    cont = 1 / (12 * np.pi * l) if l > 0 else float("inf")
    print("filtered l/h = %5.3f: K mu h = %.5f  (continuum 1/(12 pi l/h) = %.5f)" % (l, c, cont))


def build_up(y, F):
    z = F * y
    cumulative = np.concatenate([[0], np.cumsum(0.5 * (z[1:] + z[:-1]) * np.diff(t))])
    total = cumulative[-1] + 2 * (4 * np.pi) ** -1.5 / np.sqrt(t[-1])  # tail
    return t[np.searchsorted(cumulative / total, 1 - np.exp(-1))]


print("build-up to 1 - 1/e: cell %.2f h^2/nu, Q1 hat %.2f h^2/nu"
      % (build_up(I_cell ** 3, 1.0), build_up(I_hat ** 3, 1.0)))
x = np.logspace(-8, 10, 200000)
y = (1 - np.exp(-x) * (1 + x)) * x ** -1.5
cumulative = np.concatenate([[0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])
cumulative /= cumulative[-1] + 2 / np.sqrt(x[-1])
print("Helmholtz kernel (l >> h): %.1f l^2/nu" % x[np.searchsorted(cumulative, 1 - np.exp(-1))])
