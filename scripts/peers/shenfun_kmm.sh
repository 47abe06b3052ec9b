#!/usr/bin/env bash
# Peer benchmark: seconds per time step of shenfun's Kim-Moin-Moser (KMM) channel-flow solver
# (demo/ChannelFlow.py of shenfun, vendored under scripts/peers/shenfun/), against grid size,
# with 1 and 2 MPI processes. See scripts/peers/README.md.
#
# Environment (all optional):
#   SHENFUN_VENV   venv to create/use            (default $HOME/.cache/peer-venv-shenfun)
#   SHENFUN_VERSION shenfun version from PyPI     (default 4.3.0, the version the demo is from)
#   PYTHON         interpreter for the venv       (default python3)
#   GRIDS          values of N                    (default "32 64 128")
#   PROCS          MPI process counts             (default "1 2")
#   STEPS          timed steps                    (default 20)
#   WARMUP         untimed steps before timing    (default 3)
#   WALL_EXTRA     wall-normal Chebyshev points = N + WALL_EXTRA (default 0). Must give an even
#                  count: shenfun 4.3.0's Chebyshev biharmonic solver returns NaN for an odd one.
#   DEALIAS        "3/2" (shenfun's default padding (1, 1.5, 1.5)) or "none" (default 3/2)
#   RUN_TIMEOUT    seconds allowed for one (grid, procs) run (default 1800)
#   SETUP_ONLY=1   only install, run nothing
# Output: one JSON line per (grid, procs) on stdout; diagnostics on stderr.
# Exit 3 when Debian packages are missing and cannot be installed (no root, no sudo -n).
set -euo pipefail

HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="${SHENFUN_VENV:-$HOME/.cache/peer-venv-shenfun}"
SHENFUN_VERSION="${SHENFUN_VERSION:-4.3.0}"
PYTHON="${PYTHON:-python3}"
GRIDS="${GRIDS:-32 64 128}"
PROCS="${PROCS:-1 2}"
STEPS="${STEPS:-20}"
WARMUP="${WARMUP:-3}"
WALL_EXTRA="${WALL_EXTRA:-0}"
DEALIAS="${DEALIAS:-3/2}"
RUN_TIMEOUT="${RUN_TIMEOUT:-1800}"

log() { echo "[shenfun_kmm] $*" >&2; }

# ---- 1. Debian packages: an MPI (MPICH) with its compiler wrapper, and FFTW for mpi4py-fft ----
DEB_PKGS=(mpich libmpich-dev libfftw3-dev)
missing=()
for p in "${DEB_PKGS[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done
# Another MPI already providing mpicc/mpiexec is fine too (then only FFTW is needed).
if [ "${#missing[@]}" -gt 0 ] && command -v mpicc >/dev/null && command -v mpiexec >/dev/null \
        && [ -e /usr/include/fftw3.h ]; then
    log "using the MPI already on PATH ($(command -v mpiexec)) instead of Debian mpich"
    missing=()
fi
if [ "${#missing[@]}" -gt 0 ]; then
    if [ "$(id -u)" -eq 0 ]; then
        SUDO=()
    elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
        SUDO=(sudo -n)
    else
        echo "shenfun_kmm.sh: missing Debian packages: ${missing[*]}" >&2
        echo "install them with: apt-get install -y ${missing[*]}  (needs root or sudo)" >&2
        exit 3
    fi
    log "installing Debian packages: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    if ! "${SUDO[@]}" apt-get install -y -q "${missing[@]}" >&2; then
        "${SUDO[@]}" apt-get update -q >&2
        "${SUDO[@]}" apt-get install -y -q "${missing[@]}" >&2
    fi
fi

# ---- 2. Python venv with shenfun and its dependencies ----
STAMP="$VENV/.shenfun-peer-$SHENFUN_VERSION"
VPY="$VENV/bin/python"
IMPORTS='import shenfun, mpi4py, mpi4py_fft, numpy, scipy, sympy, yaml, numba'
if [ ! -e "$STAMP" ] || ! "$VPY" -c "$IMPORTS" 2>/dev/null; then
    if [ ! -x "$VENV/bin/python" ]; then
        log "creating venv $VENV"
        "$PYTHON" -m venv "$VENV"
    fi
    VPIP=("$VENV/bin/python" -m pip --disable-pip-version-check)
    "${VPIP[@]}" install -q --upgrade pip setuptools wheel cython >&2
    # pyyaml and numba: shenfun 4.3.0 imports both unconditionally (shenfun.config,
    # shenfun.optimization) but its setup.py does not declare them.
    # numpy<2.4: with numpy 2.4 shenfun 4.3.0's Cython LU_Helmholtz raises "only 0-dimensional
    # arrays can be converted to Python scalars" while assembling the KMM solvers.
    "${VPIP[@]}" install -q "numpy<2.4" scipy sympy pyyaml numba >&2
    # mpi4py built from source against the system MPI (so mpiexec and libmpi match).
    log "building mpi4py against $(command -v mpicc)"
    MPICC="$(command -v mpicc)" "${VPIP[@]}" install -q --no-binary mpi4py mpi4py >&2
    # mpi4py-fft and shenfun are sdists with C/Cython extensions.
    log "building mpi4py-fft and shenfun==$SHENFUN_VERSION"
    "${VPIP[@]}" install -q mpi4py-fft >&2
    "${VPIP[@]}" install -q "shenfun==$SHENFUN_VERSION" "numpy<2.4" >&2
    touch "$STAMP"
fi
VERSIONS="$("$VPY" -c "$IMPORTS"'; print("shenfun", shenfun.__version__, "mpi4py", mpi4py.__version__, "mpi4py_fft", mpi4py_fft.__version__, "numpy", numpy.__version__, "scipy", scipy.__version__, "sympy", sympy.__version__)')"
log "versions: $VERSIONS; MPI: $("$VPY" -c 'from mpi4py import MPI; print(MPI.Get_library_version().splitlines()[0])')"

if [ "${SETUP_ONLY:-0}" = "1" ]; then
    log "SETUP_ONLY=1: done"
    exit 0
fi

# ---- 3. Runs: one process count and grid at a time, single-threaded numerics ----
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 NUMEXPR_NUM_THREADS=1 \
       VECLIB_MAXIMUM_THREADS=1 BLIS_NUM_THREADS=1
export PYTHONDONTWRITEBYTECODE=1
MPIEXEC="${MPIEXEC:-mpiexec}"
RUNDIR="$(mktemp -d)"
trap 'rm -rf "$RUNDIR"' EXIT
status=0
for n in $GRIDS; do
    for p in $PROCS; do
        log "N=$n procs=$p steps=$STEPS warmup=$WARMUP dealias=$DEALIAS"
        if ! (cd "$RUNDIR" && timeout "$RUN_TIMEOUT" "$MPIEXEC" -n "$p" "$VPY" "$HERE/shenfun/kmm_bench.py" \
                --n "$n" --wall-extra "$WALL_EXTRA" --steps "$STEPS" --warmup "$WARMUP" \
                --dealias "$DEALIAS"); then
            log "run N=$n procs=$p failed"
            status=1
        fi
    done
done
exit "$status"
