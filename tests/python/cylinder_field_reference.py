#!/usr/bin/env python3
"""High-precision reference values for the field of a uniformly magnetised finite cylinder.

Independent of the Rust implementation: this script only uses mpmath (pure Python; gmpy2 is
used automatically if installed and makes it faster). It writes
`tests/data/cylinder_field_reference.csv`.

Geometry and units
------------------
* Circular cylinder, axis along z, centroid at the origin, radius R, HALF-length L: the body is
  rho <= R, |z| <= L. Rows use R = 1 (dimensionless lengths), but the code takes any R.
* Uniform magnetisation M = (mx, my, mz), given per row (|M| = 1 in every row; any unit, e.g.
  A/m). The reported field H = (hx, hy, hz) is in the same unit as M (mu0 factored out).
* `inside` is 1 if rho < R and |z| < L (strictly), else 0; then B/mu0 = H + inside * M.

Method
------
Magnetic surface-charge formulation. With no volume charge (div M = 0), the bound charge is
sigma = M . n on the surface: +mz on the end face z = +L, -mz on z = -L, and
mx cos(phi') + my sin(phi') on the lateral surface rho = R. Then

    H(r) = (1/4 pi) * surface-integral sigma(r') (r - r') / |r - r'|^3 dS'.

Each 2-D surface integral is reduced to a 1-D integral over the source azimuth phi' in a frame
rotated so that the field point lies at azimuth 0, i.e. at (rho, 0, z):

* lateral surface: the z' integral is done in closed form,
      int dz' / D^3         = [ t / (a^2 sqrt(a^2 + t^2)) ]_{t = z-L}^{z+L}
      int (z - z') dz'/D^3  = [ -1 / sqrt(a^2 + t^2) ]_{t = z-L}^{z+L}
  with a^2 = (rho - R)^2 + 4 R rho sin^2(phi'/2) (the horizontal distance to the source line,
  written without cancellation);
* end discs: the rho' integral is done in closed form with u = rho' - rho cos(phi'),
  b^2 = rho^2 sin^2(phi') + (z - z0)^2, using
      J0 = int du / S^3 = [u / (b^2 S)],  J1 = int u du / S^3 = [-1/S],
      J2 = int u^2 du / S^3 = [asinh(u/b) - u/S],   S = sqrt(u^2 + b^2).
All bracket differences are evaluated in cancellation-free forms (e.g. for u1, u2 of the same
sign, [u/(b^2 S)] = (u2^2 - u1^2) / (S1 S2 (u2 S1 + u1 S2)), and [-1/S] =
(u2^2 - u1^2) / (S1 S2 (S1 + S2))), so nothing blows up as b -> 0 or a -> 0.

By the mirror symmetry phi' -> -phi' only [0, pi] is integrated. Five M-independent basis
integrals are computed per field point (lateral: coefficient of m_rho in H_rho, of m_phi in
H_phi, of m_rho in H_z; ends: coefficient of mz in H_rho and H_z), so every M at that point is
a linear combination. The phi' integrals use mpmath.quad (tanh-sinh) at mp.dps = 40. The
integrand is sharply peaked at phi' = 0 (the field point's azimuth) for points close to the
lateral surface or to an end face; there the interval is split at phi' = w, 10w, 100w, ...
where w is the estimated peak width (distance to the surface over rho), and phi' = pi is the
other end point. Integrand values are cached per node, so the five quadratures share nodes.

Self-checks run before the CSV is written (the script aborts with AssertionError otherwise):
1. the golden values (R = 1, L = 3) from the magsep brief, to <= 1e-12 relative;
2. the reduced 1-D integrals against brute-force 2-D mpmath quadrature of the raw surface-charge
   integrand at a few ordinary points (dps 20, <= 1e-14 relative);
3. the closed-form on-axis field against the `near_axis` rows (difference O(rho));
4. the boundary conditions across the surface from the `near_lateral` / `near_end` pairs
   (normal H jumps by M.n, tangential H continuous, to O(d));
5. the point-dipole limit (m = M * 2 pi R^2 L) at 1000 circumscribed radii (O((a/r)^2));
6. a recomputation of the hardest points at mp.dps = 60 (agreement <= 1e-30 of |H|);
7. that every quadrature error estimate is below 1e-30;
8. optionally (--verify-dps60), every point recomputed at dps 60: each component agrees to
   <= 1e-18 of itself + 1e-35 of |H| (observed: <= 2e-19 relative, worst for the tiny O(rho^2)
   Cartesian components at rho = 1e-10 R; <= 1e-29 relative everywhere else).

CSV
---
Header `case,radius,half_length,mx,my,mz,x,y,z,hx,hy,hz,inside`. Inputs (radius ... z) are
written with Python's float repr, so they are exactly the IEEE doubles used in the computation;
hx, hy, hz are the 40-digit results rounded to 17 significant digits. Cases:

* random_axial / random_transverse / random_oblique: L/R in {0.5, 3, 20}; M = (0,0,1),
  (1,0,0) or a random unit vector with 0.1 <= |mz| <= 0.9 (transverse part in a random
  azimuth). 30 points per M kind per L/R: 10 uniform inside the body, 20 uniform in the box
  |x|, |y| <= 3R, |z| <= L + 2R; points within 1e-3 R of the surface are rejected.
* near_axis: L/R = 3; rho in {1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 1e-2} R; z in {0, 0.6 L (inside),
  L + 0.5 R (beyond the end face)}; random azimuth; all three M kinds.
* near_lateral: L/R = 3; rho = R (1 +- d), d in {1e-8, 1e-6, 1e-4}; z in {0, 1.7, -2.9}; a random
  azimuth shared by the +- pair; all three M kinds.
* near_end: L/R = 3; z = L + s d R, s = +-1, d in {1e-8, 1e-6}; rho in {0, 0.3, 0.9} R; all
  three M kinds.
* far: L/R in {3, 20}; |r| = 10, 100, 1000 a with a = sqrt(L^2 + R^2); two random directions per
  distance; all three M kinds.
* aspect: L/R in {1e-3, 1e-2, 1e3}; 10 points at distance 0.5..3 R from the body (for
  L/R = 1e3: 5 near the middle, 5 near the end z = +L) plus 2 points inside; all three M kinds.

Random draws use random.Random(20241122), so the file is reproducible.

Running
-------
    python3 tests/python/cylinder_field_reference.py            # checks, then writes the CSV
    python3 tests/python/cylinder_field_reference.py --out F    # write elsewhere
    python3 tests/python/cylinder_field_reference.py --check-only
    python3 tests/python/cylinder_field_reference.py --skip-brute     # skip check 2
    python3 tests/python/cylinder_field_reference.py --verify-dps60   # add check 8

Runtime on one core with mpmath's pure-Python backend (Python 3.11, mpmath 1.3): about
3.5 minutes (checks 1-2 take 20 s, the 366 field points 2.5 min, check 6 40 s);
--verify-dps60 adds about 4 minutes.
"""

import argparse
import math
import os
import random
import sys
import time

import mpmath as mp

DPS = 40
SEED = 20241122
HEADER = "case,radius,half_length,mx,my,mz,x,y,z,hx,hy,hz,inside"

# ---------------------------------------------------------------------------------------------
# Closed-form 1-D antiderivative differences, written without cancellation.
# ---------------------------------------------------------------------------------------------


def _d_u_over_b2s(u1, u2, du, b2):
    """[u / (b2 S)] from u1 to u2, S = sqrt(u^2 + b2); du = u2 - u1 passed exactly."""
    s1 = mp.sqrt(u1 * u1 + b2)
    s2 = mp.sqrt(u2 * u2 + b2)
    if u1 * u2 > 0:
        return du * (u1 + u2) / (s1 * s2 * (u2 * s1 + u1 * s2))
    return (u2 / s2 - u1 / s1) / b2


def _d_minus_inv_s(u1, u2, du, b2):
    """[-1 / S] from u1 to u2."""
    s1 = mp.sqrt(u1 * u1 + b2)
    s2 = mp.sqrt(u2 * u2 + b2)
    return du * (u1 + u2) / (s1 * s2 * (s1 + s2))


def _d_asinh(u1, u2, b2):
    """[asinh(u / b)] = [log(u + S)] from u1 to u2 (for u < 0 use u + S = b2 / (S - u))."""
    s1 = mp.sqrt(u1 * u1 + b2)
    s2 = mp.sqrt(u2 * u2 + b2)
    if u1 >= 0:
        return mp.log((u2 + s2) / (u1 + s1))
    if u2 <= 0:
        return mp.log((s1 - u1) / (s2 - u2))
    return mp.log((u2 + s2) * (s1 - u1) / b2)


def _d_u_over_s(u1, u2, du, b2):
    """[u / S] from u1 to u2."""
    s1 = mp.sqrt(u1 * u1 + b2)
    s2 = mp.sqrt(u2 * u2 + b2)
    if u1 * u2 > 0:
        return b2 * du * (u1 + u2) / (s1 * s2 * (u2 * s1 + u1 * s2))
    return u2 / s2 - u1 / s1


# ---------------------------------------------------------------------------------------------
# Reduced integrands and the five basis integrals at one field point.
# ---------------------------------------------------------------------------------------------


def _integrands(R, L, rho, z, ph):
    """The five phi'-integrands at source azimuth ph (field point at azimuth 0).

    Returns (A, B, C, D, E) such that, after integrating over phi' in [0, pi] and dividing
    by 2 pi (= 2 * int_0^pi / 4 pi):
        H_rho = m_rho A + mz D,  H_phi = m_phi B,  H_z = m_rho C + mz E.
    """
    c = mp.cos(ph)
    s = mp.sin(ph)
    sh = mp.sin(ph / 2)
    # Lateral surface, sigma = m_rho cos(phi') + m_phi sin(phi'), z' integrated in closed form.
    a2 = (rho - R) ** 2 + 4 * R * rho * sh * sh
    k0 = _d_u_over_b2s(z - L, z + L, 2 * L, a2)
    k1 = _d_minus_inv_s(z - L, z + L, 2 * L, a2)
    rho_minus_rc = (rho - R) + 2 * R * sh * sh  # rho - R cos(phi')
    A = R * c * rho_minus_rc * k0
    B = -R * R * s * s * k0
    C = R * c * k1
    # End discs, sigma = +-mz, rho' integrated in closed form.
    u1 = -rho * c
    u2 = R - rho * c
    D = mp.mpf(0)
    E = mp.mpf(0)
    for z0, sgn in ((L, 1), (-L, -1)):
        ze = z - z0
        b2 = rho * rho * s * s + ze * ze
        j0 = _d_u_over_b2s(u1, u2, R, b2)
        j1 = _d_minus_inv_s(u1, u2, R, b2)
        j2 = _d_asinh(u1, u2, b2) - _d_u_over_s(u1, u2, R, b2)
        # int_0^R rho' (rho - rho' cos) / D^3 drho'  and  int_0^R rho' (z - z0) / D^3 drho'
        e_rho = rho * (s * s - c * c) * j1 - c * j2 + rho * rho * c * s * s * j0
        e_z = ze * (j1 + rho * c * j0)
        D += sgn * e_rho
        E += sgn * e_z
    return (A, B, C, D, E)


def _split_points(R, L, rho, z):
    """[0, w, 10w, 100w, ..., pi] with w the angular width of the peak at phi' = 0."""
    widths = [mp.sqrt((rho - R) ** 2 + max(mp.mpf(0), abs(z) - L) ** 2) / R]
    if rho > 0:
        for z0 in (L, -L):
            widths.append(mp.sqrt(max(mp.mpf(0), rho - R) ** 2 + (z - z0) ** 2) / rho)
    w = min(widths)
    pts = [mp.mpf(0)]
    t = w
    while t < 1:
        pts.append(t)
        t *= 10
    pts.append(+mp.pi)
    return pts


class Stats:
    max_err = mp.mpf(0)
    n_points = 0
    n_evals = 0


def basis(R, L, rho, z):
    """The five basis integrals (A, B, C, D, E) at (rho, 0, z); see _integrands."""
    cache = {}

    def component(k):
        def f(ph):
            v = cache.get(ph)
            if v is None:
                v = _integrands(R, L, rho, z, ph)
                cache[ph] = v
            return v[k]

        return f

    pts = _split_points(R, L, rho, z)
    out = []
    for k in range(5):
        if rho == 0 and k in (2, 3):
            # exactly on the axis C and D vanish by symmetry (int_0^pi cos = 0); skip the
            # quadrature, which would return rounding noise instead of 0
            out.append(mp.mpf(0))
            continue
        val, err = mp.quad(component(k), pts, error=True)
        Stats.max_err = max(Stats.max_err, err / (2 * mp.pi))
        out.append(val / (2 * mp.pi))
    Stats.n_points += 1
    Stats.n_evals += len(cache)
    return out


def _azimuth(x, y):
    rho = mp.sqrt(x * x + y * y)
    if rho == 0:
        return rho, mp.mpf(1), mp.mpf(0)
    return rho, x / rho, y / rho


def field_from_basis(bas, x, y, M):
    """Cartesian H from the basis integrals at (x, y, .) and M = (mx, my, mz)."""
    A, B, C, D, E = bas
    _, cp, sp = _azimuth(x, y)
    mx, my, mz = M
    m_rho = mx * cp + my * sp
    m_phi = -mx * sp + my * cp
    h_rho = m_rho * A + mz * D
    h_phi = m_phi * B
    h_z = m_rho * C + mz * E
    return (h_rho * cp - h_phi * sp, h_rho * sp + h_phi * cp, h_z)


def field(R, L, x, y, z, M):
    R, L, x, y, z = (mp.mpf(v) for v in (R, L, x, y, z))
    M = tuple(mp.mpf(v) for v in M)
    rho, _, _ = _azimuth(x, y)
    return field_from_basis(basis(R, L, rho, z), x, y, M)


def is_inside(R, L, x, y, z):
    R, L, x, y, z = (mp.mpf(v) for v in (R, L, x, y, z))
    return 1 if (x * x + y * y < R * R and abs(z) < L) else 0


# ---------------------------------------------------------------------------------------------
# Independent brute-force 2-D quadrature of the raw surface-charge integral (for checking).
# ---------------------------------------------------------------------------------------------


def field_brute_2d(R, L, x, y, z, M):
    R, L, x, y, z = (mp.mpf(v) for v in (R, L, x, y, z))
    mx, my, mz = (mp.mpf(v) for v in M)
    phi0 = mp.atan2(y, x)
    tw = 2 * mp.pi
    # split phi' at the field point's azimuth and its opposite
    cuts = sorted({mp.mpf(0), tw, phi0 % tw, (phi0 + mp.pi) % tw})
    out = []
    for k in range(3):

        def lateral(ph, zp, k=k):
            c, s = mp.cos(ph), mp.sin(ph)
            d = (x - R * c, y - R * s, z - zp)
            r3 = (d[0] ** 2 + d[1] ** 2 + d[2] ** 2) ** mp.mpf(1.5)
            return (mx * c + my * s) * d[k] / r3 * R

        def disc(ph, rp, k=k):
            c, s = mp.cos(ph), mp.sin(ph)
            tot = 0
            for z0, sgn in ((L, 1), (-L, -1)):
                d = (x - rp * c, y - rp * s, z - z0)
                r3 = (d[0] ** 2 + d[1] ** 2 + d[2] ** 2) ** mp.mpf(1.5)
                tot += sgn * mz * d[k] / r3 * rp
            return tot

        v = mp.quad(lateral, cuts, [-L, L], method="gauss-legendre")
        v += mp.quad(disc, cuts, [0, R], method="gauss-legendre")
        out.append(v / (4 * mp.pi))
    return tuple(out)


# ---------------------------------------------------------------------------------------------
# Checks.
# ---------------------------------------------------------------------------------------------


def _rel(a, b):
    return abs(a - b) / abs(b)


def check_golden():
    R, L = 1, 3
    rows = [
        # rho, phi, z, H_rho, H_phi, H_z (M = x),  B_rho/mu0, B_z/mu0 (M = z)
        (0.5, 0.3, 0.7, "-0.4513802587267", "0.1392616618729", "5.147189661406e-3",
         "5.387829021497e-3", "0.9437254440432"),
        (1.5, 0.3, 0.7, "0.2280799521451", "0.05841750347535", "0.01004398149553",
         "0.01051355371626", "-0.04106620548715"),
        (10, 0.4, 25, "-4.140744068523e-5", "3.049203493912e-5", "7.534758517828e-5",
         "8.180520689604e-5", "1.232577278758e-4"),
    ]
    worst = mp.mpf(0)
    for rho, ph, z, *gold in rows:
        rho, ph, z = mp.mpf(rho), mp.mpf(ph), mp.mpf(z)
        x, y = rho * mp.cos(ph), rho * mp.sin(ph)
        cp, sp = mp.cos(ph), mp.sin(ph)
        hx = field(R, L, x, y, z, (1, 0, 0))
        hz = field(R, L, x, y, z, (0, 0, 1))
        ins = is_inside(R, L, x, y, z)
        got = [
            hx[0] * cp + hx[1] * sp,
            -hx[0] * sp + hx[1] * cp,
            hx[2],
            hz[0] * cp + hz[1] * sp,
            hz[2] + ins,
        ]
        for g, w in zip(got, gold):
            r = _rel(g, mp.mpf(w))
            worst = max(worst, r)
            assert r <= 1e-12, ("golden", float(rho), float(z), mp.nstr(g, 16), w)
    bz0 = field(R, L, 0, 0, 0, (0, 0, 1))[2] + 1
    hx0 = field(R, L, 0, 0, 0, (1, 0, 0))[0]
    for g, w in ((bz0, "0.948683298050514"), (hx0, "-0.474341649025257")):
        r = _rel(g, mp.mpf(w))
        worst = max(worst, r)
        assert r <= 1e-12, ("golden axis", mp.nstr(g, 16), w)
    # exact closed forms of the two axis values: L / sqrt(L^2 + R^2) and half of it
    exact = mp.mpf(3) / mp.sqrt(10)
    assert abs(bz0 - exact) < mp.mpf(10) ** (-35) and abs(hx0 + exact / 2) < mp.mpf(10) ** (-35)
    return worst


def check_brute():
    pts = [
        (1, 3, (0.31, -0.42, 0.77), (0.36, -0.48, 0.8)),  # inside
        (1, 0.5, (1.3, 0.9, -0.2), (0.6, 0.64, 0.48)),  # outside, beside the lateral surface
        (1, 0.5, (-0.4, 0.25, 1.6), (-0.28, 0.96, 0.0)),  # outside, beyond an end face
    ]
    worst = mp.mpf(0)
    with mp.workdps(20):
        for R, L, (x, y, z), M in pts:
            a = field(R, L, x, y, z, M)
            b = field_brute_2d(R, L, x, y, z, M)
            scale = max(abs(v) for v in b)
            for u, v in zip(a, b):
                r = abs(u - v) / scale
                worst = max(worst, r)
                assert r < 1e-14, ("brute", (x, y, z), mp.nstr(u, 18), mp.nstr(v, 18))
    return worst


def axis_field(R, L, z, M):
    """Closed-form H on the axis (rho = 0)."""
    R, L, z = mp.mpf(R), mp.mpf(L), mp.mpf(z)
    mx, my, mz = (mp.mpf(v) for v in M)
    f = (z + L) / mp.sqrt((z + L) ** 2 + R * R) - (z - L) / mp.sqrt((z - L) ** 2 + R * R)
    ins = 1 if abs(z) < L else 0
    return (-mx * f / 4, -my * f / 4, mz * f / 2 - ins * mz)


def dipole_field(R, L, x, y, z, M):
    R, L, x, y, z = (mp.mpf(v) for v in (R, L, x, y, z))
    V = 2 * mp.pi * R * R * L
    m = [mp.mpf(v) * V for v in M]
    r = mp.sqrt(x * x + y * y + z * z)
    n = (x / r, y / r, z / r)
    mn = sum(a * b for a, b in zip(m, n))
    return tuple((3 * mn * n[k] - m[k]) / (4 * mp.pi * r**3) for k in range(3))


# ---------------------------------------------------------------------------------------------
# Cases.
# ---------------------------------------------------------------------------------------------


def dist_to_surface(R, L, x, y, z):
    rho = math.hypot(x, y)
    if rho < R and abs(z) < L:
        return min(R - rho, L - abs(z))
    return math.hypot(max(0.0, rho - R), max(0.0, abs(z) - L))


def random_oblique(rng):
    while True:
        mz = 2 * rng.random() - 1
        if 0.1 <= abs(mz) <= 0.9:
            break
    t = math.sqrt(1 - mz * mz)
    az = 2 * math.pi * rng.random()
    return (t * math.cos(az), t * math.sin(az), mz)


AXIAL = (0.0, 0.0, 1.0)
TRANSVERSE = (1.0, 0.0, 0.0)


def three_kinds(rng):
    return [AXIAL, TRANSVERSE, random_oblique(rng)]


def build_cases(rng):
    """List of (case, R, L, [M, ...], (x, y, z), tag) with all floats as Python doubles."""
    R = 1.0
    cases = []
    # random_*: separate random points for each M kind
    for L in (0.5, 3.0, 20.0):
        for kind in ("axial", "transverse", "oblique"):
            n_in = 0
            n_box = 0
            while n_in + n_box < 30:
                want_inside = n_in < 10
                if want_inside:
                    x, y, z = ((2 * rng.random() - 1) * R, (2 * rng.random() - 1) * R,
                               (2 * rng.random() - 1) * L)
                    if math.hypot(x, y) >= R:
                        continue
                else:
                    x, y, z = ((2 * rng.random() - 1) * 3 * R, (2 * rng.random() - 1) * 3 * R,
                               (2 * rng.random() - 1) * (L + 2 * R))
                if dist_to_surface(R, L, x, y, z) < 1e-3 * R:
                    continue
                M = {"axial": AXIAL, "transverse": TRANSVERSE}.get(kind) or random_oblique(rng)
                cases.append(("random_" + kind, R, L, [M], (x, y, z), None))
                if want_inside:
                    n_in += 1
                else:
                    n_box += 1
    L = 3.0
    # near_axis
    for rr in (1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 1e-2):
        for z in (0.0, 0.6 * L, L + 0.5 * R):
            az = 2 * math.pi * rng.random()
            p = (rr * R * math.cos(az), rr * R * math.sin(az), z)
            cases.append(("near_axis", R, L, three_kinds(rng), p, ("axis", rr)))
    # near_lateral: +- pairs share the azimuth
    for d in (1e-8, 1e-6, 1e-4):
        for z in (0.0, 1.7, -2.9):
            az = 2 * math.pi * rng.random()
            kinds = three_kinds(rng)
            for s in (1, -1):
                rho = R * (1 + s * d)
                p = (rho * math.cos(az), rho * math.sin(az), z)
                cases.append(("near_lateral", R, L, kinds, p, ("lat", d, z, s)))
    # near_end: +- pairs share rho and azimuth
    for d in (1e-8, 1e-6):
        for rr in (0.0, 0.3, 0.9):
            az = 2 * math.pi * rng.random()
            kinds = three_kinds(rng)
            for s in (1, -1):
                p = (rr * R * math.cos(az), rr * R * math.sin(az), L + s * d * R)
                cases.append(("near_end", R, L, kinds, p, ("end", d, rr, s)))
    # far
    for L in (3.0, 20.0):
        a = math.sqrt(L * L + R * R)
        for k in (10, 100, 1000):
            for _ in range(2):
                cz = 2 * rng.random() - 1
                az = 2 * math.pi * rng.random()
                t = math.sqrt(1 - cz * cz)
                r = k * a
                p = (r * t * math.cos(az), r * t * math.sin(az), r * cz)
                cases.append(("far", R, L, three_kinds(rng), p, ("far", k)))
    # aspect
    for L in (1e-3, 1e-2, 1e3):
        pts = []
        if L < 1:
            while len(pts) < 10:
                p = ((2 * rng.random() - 1) * 4 * R, (2 * rng.random() - 1) * 4 * R,
                     (2 * rng.random() - 1) * (L + 3 * R))
                if 0.5 * R <= dist_to_surface(R, L, *p) <= 3 * R:
                    pts.append(p)
            for _ in range(2):
                rr, az = 0.9 * R * rng.random(), 2 * math.pi * rng.random()
                pts.append((rr * math.cos(az), rr * math.sin(az), (2 * rng.random() - 1) * 0.5 * L))
        else:
            for zc in (0.0, L):
                n = 0
                while n < 5:
                    p = ((2 * rng.random() - 1) * 4 * R, (2 * rng.random() - 1) * 4 * R,
                         zc + (2 * rng.random() - 1) * 3 * R)
                    if 0.5 * R <= dist_to_surface(R, L, *p) <= 3 * R:
                        pts.append(p)
                        n += 1
            for zc in (0.0, L - 0.5 * R):
                rr, az = 0.9 * R * rng.random(), 2 * math.pi * rng.random()
                pts.append((rr * math.cos(az), rr * math.sin(az), zc))
        for p in pts:
            cases.append(("aspect", R, L, three_kinds(rng), p, ("aspect",)))
    return cases


def fmt_in(v):
    return repr(float(v) + 0.0)  # + 0.0 turns -0.0 into 0.0


def fmt_out(v):
    return mp.nstr(v, 17, min_fixed=-4, max_fixed=4)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--out", default=os.path.join(here, "..", "data",
                                                  "cylinder_field_reference.csv"))
    ap.add_argument("--check-only", action="store_true", help="run the checks, write nothing")
    ap.add_argument("--skip-brute", action="store_true", help="skip the slow 2-D check")
    ap.add_argument("--verify-dps60", action="store_true",
                    help="recompute every point at dps 60 and compare component-wise (slow)")
    args = ap.parse_args()
    mp.mp.dps = DPS
    t0 = time.time()

    def log(msg):
        print(f"[{time.time() - t0:7.1f}s] {msg}", flush=True)

    worst = check_golden()
    log(f"golden values OK, worst relative deviation {mp.nstr(worst, 3)}")
    if not args.skip_brute:
        worst = check_brute()
        log(f"brute-force 2-D quadrature OK, worst relative deviation {mp.nstr(worst, 3)}")

    Stats.max_err = mp.mpf(0)  # the checks above ran partly at dps 20
    rng = random.Random(SEED)
    cases = build_cases(rng)
    log(f"{len(cases)} field points, {sum(len(c[3]) for c in cases)} rows")
    rows = []
    results = {}  # tag-keyed results for the cross checks
    counts = {}
    last = None
    for i, (case, R, L, Ms, p, tag) in enumerate(cases):
        if case != last:
            log(f"case {case} ...")
            last = case
        x, y, z = (mp.mpf(v) for v in p)
        rho, _, _ = _azimuth(x, y)
        bas = basis(mp.mpf(R), mp.mpf(L), rho, z)
        ins = is_inside(R, L, *p)
        for M in Ms:
            H = field_from_basis(bas, x, y, tuple(mp.mpf(v) for v in M))
            rows.append((case, R, L, M, p, H, ins))
            counts[case] = counts.get(case, 0) + 1
            if tag is not None:
                results.setdefault(tag, []).append((R, L, M, p, H, ins, bas))
        if (i + 1) % 25 == 0:
            log(f"  {i + 1}/{len(cases)} points done")
    log(f"all points done; {Stats.n_evals} integrand evaluations; "
        f"max quadrature error estimate {mp.nstr(Stats.max_err, 3)}")
    assert Stats.max_err < 1e-30, "quadrature error estimate too large"

    # Check: closed-form axis field, difference O(rho)
    worst = 0
    for tag, lst in results.items():
        if tag[0] != "axis":
            continue
        for R, L, M, p, H, ins, _ in lst:
            ref = axis_field(R, L, p[2], M)
            dev = max(abs(a - b) for a, b in zip(H, ref))
            worst = max(worst, dev / tag[1])
            assert dev <= 2 * tag[1], ("axis", tag, p, M, dev)
    log(f"near_axis vs closed-form axis field OK: max |dH| / rho = {mp.nstr(worst, 3)}")

    # Check: surface boundary conditions from the +- pairs
    worst = 0
    for tag, lst in results.items():
        if tag[0] not in ("lat", "end") or tag[-1] != 1:
            continue
        inner = results[tag[:-1] + (-1,)]
        d = tag[1]
        for (R, L, M, p, Ho, io, _), (_, _, M2, p2, Hi, ii, _) in zip(lst, inner):
            assert M == M2 and io == 0 and ii == 1
            x, y, z = (mp.mpf(v) for v in p)
            if tag[0] == "lat":
                _, cp, sp = _azimuth(x, y)
                n = (cp, sp, 0)
            else:
                n = (0, 0, 1)
            mn = sum(mp.mpf(a) * b for a, b in zip(M, n))
            # H_out - H_in = (M . n) n  (normal B and tangential H continuous)
            dev = max(abs(Ho[k] - Hi[k] - mn * n[k]) for k in range(3))
            worst = max(worst, dev / d)
            assert dev <= 100 * d, ("jump", tag, M, dev)
    log(f"surface jump conditions OK: max deviation / d = {mp.nstr(worst, 3)}")

    # Check: dipole limit at 1000 a
    worst = 0
    for tag, lst in results.items():
        if tag != ("far", 1000):
            continue
        for R, L, M, p, H, ins, _ in lst:
            ref = dipole_field(R, L, *p, M)
            scale = max(abs(v) for v in ref)
            dev = max(abs(a - b) for a, b in zip(H, ref)) / scale
            worst = max(worst, dev)
            assert dev < 1e-5, ("dipole", p, M, dev)
    log(f"far field vs point dipole at 1000 a OK: max relative deviation {mp.nstr(worst, 3)}")

    # Check: recompute the hardest points at higher precision
    hard = [c for c in cases if c[5] is not None and (
        (c[5][0] == "axis" and c[5][1] == 1e-10) or (c[5][0] in ("lat", "end") and c[5][1] == 1e-8)
        or c[5] == ("far", 1000))]
    hard += [c for c in cases if c[0] == "aspect"][::6]
    worst = 0
    for case, R, L, Ms, p, tag in hard:
        x, y, z = (mp.mpf(v) for v in p)
        rho, _, _ = _azimuth(x, y)
        b40 = [mp.mpf(v) for v in basis(mp.mpf(R), mp.mpf(L), rho, z)]
        with mp.workdps(60):
            x, y, z = (mp.mpf(v) for v in p)
            rho, _, _ = _azimuth(x, y)
            b60 = basis(mp.mpf(R), mp.mpf(L), rho, z)
            for M in Ms:
                Mm = tuple(mp.mpf(v) for v in M)
                h40 = field_from_basis(b40, x, y, Mm)
                h60 = field_from_basis(b60, x, y, Mm)
                scale = max(abs(v) for v in h60)
                dev = max(abs(a - b) for a, b in zip(h40, h60)) / scale
                worst = max(worst, dev)
                assert dev < 1e-30, ("dps60", case, p, M, dev)
    log(f"{len(hard)} hardest points recomputed at dps 60: max deviation {mp.nstr(worst, 3)} |H|")

    if args.verify_dps60:
        worst = 0
        j = 0
        for i, (case, R, L, Ms, p, tag) in enumerate(cases):
            with mp.workdps(60):
                x, y, z = (mp.mpf(v) for v in p)
                rho, _, _ = _azimuth(x, y)
                b60 = basis(mp.mpf(R), mp.mpf(L), rho, z)
                for M in Ms:
                    h60 = field_from_basis(b60, x, y, tuple(mp.mpf(v) for v in M))
                    h40 = rows[j][5]
                    j += 1
                    scale = max(abs(v) for v in h60)
                    for a, b in zip(h40, h60):
                        dev = abs(a - b)
                        worst = max(worst, dev / abs(b) if b != 0 else dev / scale)
                        assert dev <= 1e-18 * abs(b) + 1e-35 * scale, ("verify", case, p, M)
            if (i + 1) % 50 == 0:
                log(f"  dps-60 verification {i + 1}/{len(cases)}")
        log(f"every point recomputed at dps 60: max component-wise relative deviation "
            f"{mp.nstr(worst, 3)}")

    for case, n in counts.items():
        log(f"  {case:18s} {n:4d} rows")
    if args.check_only:
        log("check-only: nothing written")
        return
    out = os.path.normpath(args.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, "w") as f:
        f.write(HEADER + "\n")
        for case, R, L, M, p, H, ins in rows:
            vals = [fmt_in(R), fmt_in(L)] + [fmt_in(v) for v in M] + [fmt_in(v) for v in p]
            vals += [fmt_out(v) for v in H]
            f.write(",".join([case] + vals + [str(ins)]) + "\n")
    log(f"wrote {len(rows)} rows to {out}")


if __name__ == "__main__":
    sys.exit(main())
