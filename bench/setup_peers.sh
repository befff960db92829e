#!/usr/bin/env bash
# Installs the benchmark peers (libigl, CHOLMOD via scikit-sparse, xatlas) into a
# Python venv at bench/.venv. Idempotent. Called by bench/run.sh.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --upgrade pip >/dev/null
"$venv/bin/pip" install --quiet numpy scipy libigl xatlas
# CHOLMOD: scikit-sparse needs SuiteSparse headers when no wheel fits this platform.
if ! "$venv/bin/python" -c "import sksparse.cholmod" 2>/dev/null; then
  # 0.4.16 builds against Debian 12's SuiteSparse 5.x; 0.5 needs SuiteSparse 7.
  if [ ! -f /usr/include/suitesparse/cholmod.h ] && command -v apt-get >/dev/null; then
    (apt-get update -qq && apt-get install -y -qq libsuitesparse-dev) >/dev/null 2>&1 || true
  fi
  "$venv/bin/pip" install --quiet "scikit-sparse==0.4.16" \
    || echo "warning: scikit-sparse (CHOLMOD) could not be installed; the factorisation peer will be missing" >&2
fi
"$venv/bin/python" - <<'PY'
import importlib
for m in ["numpy", "scipy", "igl", "xatlas", "sksparse.cholmod"]:
    try:
        importlib.import_module(m); print(f"peer {m}: ok")
    except Exception as e:
        print(f"peer {m}: MISSING ({e})")
PY
