#!/usr/bin/env bash
# Installs the peers of scripts/peers/run.py (issue 32). Idempotent: a second run installs
# nothing new and exits 0.
#
# Debian packages (apt-get, only those not installed yet):
#   libllvm15        LLVM 15 shared library: Dr.Jit's LLVM back end JIT-compiles Mitsuba's
#                    llvm_ad_rgb kernels with it (found through DRJIT_LIBLLVM_PATH)
#   libegl1          the EGL loader (GLVND)
#   libegl-mesa0     Mesa's EGL vendor library (surfaceless platform)
#   libgl1-mesa-dri  Mesa's drivers, llvmpipe among them
#   libgl1           the OpenGL loader (GLVND)
# Python packages, into the virtual environment scripts/peers/.venv (not committed):
#   mitsuba 3.9.1 (with drjit; its llvm_ad_rgb variant ray-traces on the CPU with Embree),
#   numpy, PyOpenGL.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
debs=(libllvm15 libegl1 libegl-mesa0 libgl1-mesa-dri libgl1)
pips=("mitsuba==3.9.1" "numpy" "PyOpenGL==3.1.10")

missing=()
for p in "${debs[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done
if ((${#missing[@]})); then
    sudo=()
    if [ "$(id -u)" -ne 0 ]; then sudo=(sudo); fi
    echo "setup: apt-get install ${missing[*]}"
    "${sudo[@]}" apt-get update
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
else
    echo "setup: Debian packages present: ${debs[*]}"
fi

if [ ! -x "$venv/bin/python" ]; then
    echo "setup: python3 -m venv $venv"
    python3 -m venv "$venv"
fi
if "$venv/bin/python" -c 'import mitsuba, drjit, numpy, OpenGL' 2>/dev/null; then
    echo "setup: Python packages present in $venv"
else
    echo "setup: pip install ${pips[*]}"
    "$venv/bin/python" -m pip install --quiet --upgrade pip
    "$venv/bin/python" -m pip install --quiet "${pips[@]}"
fi

# The check: Mitsuba's llvm_ad_rgb variant and an EGL context on llvmpipe.
"$venv/bin/python" "$here/run.py" --check
