#!/usr/bin/env bash
# Installs what strata needs to build on Debian 12, idempotently:
#   - libclang (bindgen in embree4-sys needs the full -dev package for stddef.h), pkg-config
#   - Embree 4.4 + TBB into ./.embree/lib, from the PyPI wheel embreex==4.4.0.post1
#     (skipped when EMBREE_DIR is set or pkg-config finds embree4)
#   - Debian's chromium (headless: the browser test of report.html, tests/it/report_html.rs)
#   - NVIDIA's flip-evaluator (FLIP's reference implementation, with numpy) into target/py, for
#     tests/it/flip.rs (pip --target: no system packages touched)
#   - a Rust toolchain is assumed (cargo on PATH); rustup is used to install it if missing.
#   - with --python: the project virtualenv .venv (maturin, numpy, pytest, matplotlib from PyPI)
#     with the `strata` Python module built into it (scripts/test.sh asks for it).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
python_module=
for a in "$@"; do
  case "$a" in
    --python) python_module=1 ;;
    *) echo "setup: unknown option $a (known: --python)" >&2; exit 2 ;;
  esac
done

need_apt=()
dpkg -s libclang-dev >/dev/null 2>&1 || need_apt+=(libclang-dev)
command -v pkg-config >/dev/null 2>&1 || need_apt+=(pkg-config)
command -v python3 >/dev/null 2>&1 || need_apt+=(python3)
python3 -m pip --version >/dev/null 2>&1 || need_apt+=(python3-pip)
command -v chromium >/dev/null 2>&1 || need_apt+=(chromium)
# The Python module's virtualenv needs venv with ensurepip (Debian's python3-venv).
[ -z "$python_module" ] || python3 -c 'import ensurepip, venv' >/dev/null 2>&1 || need_apt+=(python3-venv)
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "setup: installing ${need_apt[*]}" >&2
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

if ! PYTHONPATH="$root/target/py" python3 -c "import flip_evaluator, numpy" >/dev/null 2>&1; then
  echo "setup: installing flip-evaluator (FLIP's reference) into target/py" >&2
  python3 -m pip install -q --upgrade --disable-pip-version-check --root-user-action=ignore --target "$root/target/py" \
    flip-evaluator==1.7 numpy
fi

if ! command -v cargo >/dev/null 2>&1; then
  [ -x "$HOME/.cargo/bin/cargo" ] && export PATH="$HOME/.cargo/bin:$PATH"
fi
command -v cargo >/dev/null 2>&1 || { echo "setup: cargo not found; install Rust with rustup first" >&2; exit 1; }

embree_ready() {
  [ -n "${EMBREE_DIR:-}" ] && return 0
  pkg-config --exists embree4 2>/dev/null && return 0
  [ -e "$root/.embree/lib/libembree4.so" ] && ls "$root/.embree/lib"/libtbb*.so* >/dev/null 2>&1
}
if ! embree_ready; then
lib="$root/.embree/lib"
echo "setup: fetching Embree 4.4 from the PyPI wheel embreex==4.4.0.post1 into .embree/" >&2
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.11 \
  --platform manylinux_2_28_x86_64 embreex==4.4.0.post1 -d "$tmp"
mkdir -p "$lib"
python3 - "$tmp"/embreex-*.whl "$lib" <<'PY'
import sys, zipfile, os
whl, out = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(whl) as z:
    for n in z.namelist():
        if n.startswith("embreex.libs/") and ".so" in n:
            dst = os.path.join(out, os.path.basename(n))
            with z.open(n) as src, open(dst, "wb") as f:
                f.write(src.read())
PY
emb="$(ls "$lib"/libembree4-*.so.4 | head -n1)"
ln -sf "$(basename "$emb")" "$lib/libembree4.so"
ln -sf "$(basename "$emb")" "$lib/libembree4.so.4"
echo "setup: Embree ready in $lib" >&2
fi

# ---- Python module (issue 24; `--python`): .venv with maturin, numpy, pytest, matplotlib and the
# ---- `strata` module built from python/ (sharing target/ with the renderer). Idempotent: the
# ---- packages are installed once (a stamp lists them); cargo rebuilds the module only on change.
if [ -n "$python_module" ]; then
  venv="$root/.venv"
  [ -x "$venv/bin/python" ] || python3 -m venv "$venv"
  want="maturin>=1.5,<2 numpy pytest matplotlib"
  if [ "$(cat "$venv/.strata-packages" 2>/dev/null)" != "$want" ]; then
    echo "setup: installing $want into .venv" >&2
    # shellcheck disable=SC2086
    "$venv/bin/python" -m pip install -q $want
    echo "$want" >"$venv/.strata-packages"
  fi
  # STRATA_PROFILE: the cargo profile (release; scripts/test.sh builds with its own, ci).
  profile="${STRATA_PROFILE:-release}"
  echo "setup: building the strata Python module into .venv (maturin develop --profile $profile)" >&2
  (cd "$root/python" && VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" maturin develop --profile "$profile" --quiet)
fi
