"""Time shenfun's KMM channel solver (vendored ChannelFlow.py, unchanged): seconds per step.

Run under MPI by ../shenfun_kmm.sh:  mpiexec -n P python kmm_bench.py --n N [...]

- The solver is shenfun's own class ChannelFlow.KMM (Kim-Moin-Moser wall-normal velocity /
  wall-normal vorticity formulation, Chebyshev-Galerkin wall-normal, Fourier in the two
  periodic directions, IMEXRK3 time stepper, conv=0 i.e. convective form u.grad(u)).
- Only file output is removed: ShenfunFile and Checkpoint are replaced by no-op stubs in the
  ChannelFlow module namespace (the stock Checkpoint opens an HDF5 file with the "mpio" driver
  at the first step and lists the working directory every step; the stock demo writes nothing
  else unless modsave/checkpoint steps are reached).
- The timed loop is the loop body of KMM.solve() (three RK stages of prepare_step/convection,
  compute_rhs, solve_step, compute_vw, then update()) without the matrix assembly that
  KMM.solve() does on every call, so setup is excluded.
- Initial condition: laminar Poiseuille flow v = 1 - x^2 (x wall-normal, driven by
  dp/dy = -2/Re as in shenfun's OrrSommerfeld demo) plus a small smooth 3D disturbance in the
  wall-normal velocity, eps (1-x^2)^2 sin(y) cos(2z), so that every term is non-trivial and
  the run stays finite.

Licence: this driver is part of magsep's scripts; ChannelFlow.py beside it is shenfun's
(BSD-2-Clause, notice in that file).
"""
import argparse
import datetime
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
import shenfun  # noqa: E402
from shenfun import Array, config, inner  # noqa: E402

import ChannelFlow  # noqa: E402  (shenfun demo, vendored)

comm = MPI.COMM_WORLD
rank = comm.Get_rank()


def err(*a):
    if rank == 0:
        print("[kmm_bench]", *a, file=sys.stderr, flush=True)


class _NoFile:
    def __init__(self, *a, **k):
        pass

    def write(self, *a, **k):
        pass


class _NoCheckpoint:
    def __init__(self, *a, **k):
        pass

    def update(self, *a, **k):
        pass


ChannelFlow.ShenfunFile = lambda *a, **k: _NoFile()
ChannelFlow.Checkpoint = _NoCheckpoint


class BenchKMM(ChannelFlow.KMM):
    def __init__(self, N, Re, dt, padding_factor, timestepper):
        ChannelFlow.KMM.__init__(self, N=N, nu=1.0 / Re, dt=dt, conv=0, dpdy=-2.0 / Re,
                                 filename="KMM_bench", family="C",
                                 padding_factor=padding_factor, modplot=-1, modsave=1e8,
                                 moderror=-1, checkpoint=10**9, timestepper=timestepper)
        self.Re = Re

    def initialize(self, from_checkpoint=False, eps=1e-3):
        x, y, z = self.X
        U = Array(self.BD)
        U[0] = eps * (1 - x**2)**2 * np.sin(y) * np.cos(2 * z)
        U[1] = 1 - x**2
        U[2] = 0
        u_ = U.forward(self.u_)
        u_.mask_nyquist(self.mask)
        self.g_[:] = 1j * self.K[1] * u_[2] - 1j * self.K[2] * u_[1]
        return 0.0, 0

    def one_step(self, t, tstep):
        # Loop body of KMM.solve() (ChannelFlow.py), checkpoint/file output stubbed out.
        for rk in range(self.PDE.steps()):
            self.prepare_step(rk)
            for eq in self.pdes.values():
                eq.compute_rhs(rk)
            for eq in self.pdes.values():
                eq.solve_step(rk)
            self.compute_vw(rk)
        t += self.dt
        tstep += 1
        self.update(t, tstep)
        self.checkpoint.update(t, tstep)
        if tstep % self.modsave == 0:
            self.tofile(tstep)
        return t, tstep

    def diagnostics(self):
        ub = self.u_.backward()
        e = [float(inner(1, ub[i] * ub[i])) for i in range(3)]
        divu = self.divu().backward()
        d = float(np.sqrt(inner(1, divu * divu)))
        return e, d


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, required=True, help="Fourier points per periodic direction")
    ap.add_argument("--wall-extra", type=int, default=0,
                    help="wall-normal quadrature points = n + wall_extra (must be even)")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--warmup", type=int, default=3)
    ap.add_argument("--dealias", choices=["3/2", "none"], default="3/2")
    ap.add_argument("--re", type=float, default=2000.0)
    ap.add_argument("--dt", type=float, default=0.005)
    ap.add_argument("--timestepper", default="IMEXRK3")
    a = ap.parse_args()

    config["optimization"]["mode"] = "cython"  # as shenfun's channel demos set it
    n = a.n
    n_wall = n + a.wall_extra
    if n_wall % 2:
        # shenfun 4.3.0: chebyshev.la.Biharmonic (the solver of the wall-normal velocity
        # equation) returns NaN for every wavenumber when the Chebyshev count is odd.
        err(f"wall-normal count {n_wall} is odd; shenfun's Chebyshev biharmonic solver "
            "gives NaN for odd counts: use an even N + WALL_EXTRA")
        sys.exit(2)
    N = (n_wall, n, n)  # shenfun's order: x wall-normal, y streamwise, z spanwise
    padding = (1, 1.5, 1.5) if a.dealias == "3/2" else (1, 1, 1)

    t_setup = time.perf_counter()
    c = BenchKMM(N, a.re, a.dt, padding, a.timestepper)
    t, tstep = c.initialize()
    c.assemble()
    comm.Barrier()
    t_setup = time.perf_counter() - t_setup
    err(f"N={N} procs={comm.Get_size()} setup {t_setup:.2f} s; quad={c.B0.quad} "
        f"dims biharmonic={c.B0.dim()} dirichlet={c.D0.dim()} padded={c.TDp.shape(False)} "
        f"spectral shape={c.TB.shape(True)} local={c.u_.shape}")

    for _ in range(a.warmup):
        t, tstep = c.one_step(t, tstep)
    comm.Barrier()

    per_step = []
    t_total = MPI.Wtime()
    for _ in range(a.steps):
        t0 = MPI.Wtime()
        t, tstep = c.one_step(t, tstep)
        comm.Barrier()
        per_step.append(MPI.Wtime() - t0)
    t_total = MPI.Wtime() - t_total
    t_total = comm.allreduce(t_total, op=MPI.MAX)

    e, d = c.diagnostics()
    finite = bool(np.all(np.isfinite(e)) and np.isfinite(d))
    err(f"after {tstep} steps t={t:.4f}: energy {e[0]:.6e} {e[1]:.6e} {e[2]:.6e} "
        f"div {d:.3e} finite={finite}")

    if rank == 0:
        per_step = np.array(per_step)
        out = {
            "impl": "shenfun",
            "version": shenfun.__version__,
            "case": "kmm_channel",
            "grid": [n, n, n_wall],
            "procs": comm.Get_size(),
            "steps": a.steps,
            "seconds_per_step": round(t_total / a.steps, 6),
            "dealias": a.dealias,
            "grid_axes": ["streamwise Fourier points", "spanwise Fourier points",
                          "wall-normal Chebyshev quadrature points (%s)" % c.B0.quad],
            "wall_normal_dofs": {"wall_normal_velocity_biharmonic": c.B0.dim(),
                                 "vorticity_dirichlet": c.D0.dim()},
            "fourier_modes": [n, n // 2 + 1],
            "padded_physical_grid": [int(round(n * padding[1])), int(round(n * padding[2])),
                                     n_wall],
            "timestepper": a.timestepper,
            "rk_stages_per_step": c.PDE.steps(),
            "warmup_steps": a.warmup,
            "seconds_per_step_median": round(float(np.median(per_step)), 6),
            "seconds_per_step_min": round(float(per_step.min()), 6),
            "setup_seconds": round(t_setup, 3),
            "finite": finite,
            "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        }
        print(json.dumps(out), flush=True)
    if not finite:
        sys.exit(2)


if __name__ == "__main__":
    try:
        main()
    except SystemExit as e:
        if e.code not in (0, None):
            comm.Abort(int(e.code) if isinstance(e.code, int) else 1)
        raise
    except BaseException:
        # One failing rank would otherwise leave the others spinning in a collective.
        import traceback
        traceback.print_exc()
        sys.stderr.flush()
        comm.Abort(1)
