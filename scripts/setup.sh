#!/usr/bin/env bash
# Install everything shadermatrix needs on Debian 12, as root. Idempotent; pinned.
# Versions live here, in generator/toolchain/pins.toml (the tools) and requirements.lock; docs/guide/install.md says why.
set -euo pipefail
cd "$(dirname "$0")/.."

# The tools' versions have one source, generator/toolchain/pins.toml (package data: `shadermatrix doctor`
# checks the tools against the same file); its lines are `name = "version"`.
pin() {
  sed -n "s/^$1 *= *\"\([^\"]*\)\".*/\1/p" generator/toolchain/pins.toml | grep . ||
    { echo "setup: no pin for $1 in generator/toolchain/pins.toml" >&2; return 1; }
}
GLSLC_V=$(pin glslc); GLSLANG_V=$(pin glslang-tools); SPIRV_TOOLS_V=$(pin spirv-tools)
MESA_V=$(pin mesa-vulkan-drivers); NAGA_VERSION=$(pin naga)

# Debian 12 (bookworm) packages, pinned to the versions in bookworm + security.
APT_PKGS=(
  "libvulkan1=1.3.239.0-1"                 # Vulkan loader
  "vulkan-validationlayers=1.3.239.0-2"    # VK_LAYER_KHRONOS_validation for tests
  "glslc=$GLSLC_V"                         # shaderc: batches many GLSL/HLSL compiles in one process
  "glslang-tools=$GLSLANG_V"               # glslangValidator (HLSL front end, version reporting)
  "spirv-tools=$SPIRV_TOOLS_V"             # spirv-val, spirv-opt, spirv-as, spirv-dis
  # The C side (include/shadermatrix/pack.h, examples/engine-c): gcc builds the engine, gcc and g++ compile
  # pack.h as C and C++17 in its tests; Vulkan's headers, cJSON, and clang for AddressSanitizer,
  # UndefinedBehaviorSanitizer and libFuzzer
  "gcc=4:12.2.0-3"
  "g++=4:12.2.0-3"
  "libvulkan-dev=1.3.239.0-1"
  "libcjson-dev=1.7.15-1+deb12u4"
  "libcjson1=1.7.15-1+deb12u4"
  "clang-14=1:14.0.6-12"
  "libclang-rt-14-dev=1:14.0.6-12"
  # the build systems an engine drives `shadermatrix build` from, run for real by the build-integration tests
  "cmake=3.25.1-1"
  "ninja-build=1.11.1-2~deb12u1"
  "make=4.3-4.1"
)
# Mesa from bookworm-backports, pinned: its shader disk cache reports hits and misses
# (MESA_SHADER_CACHE_SHOW_STATS; Mesa 22.3 cannot), which is how a render shows that it was served
# from its persisted cache (lavapipe's VkPipelineCache stays empty in both). The libdrm and
# gallium versions are the ones this Mesa needs. bookworm-backports keeps only its latest upload:
# when these versions are gone, set-up says so; bump them to what `apt-cache policy
# mesa-vulkan-drivers` offers from bookworm-backports (mesa's in generator/toolchain/pins.toml; docs/guide/install.md).
BPO_PKGS=(
  "mesa-vulkan-drivers=$MESA_V"            # lavapipe (software Vulkan 1.4) and RADV
  "mesa-libgallium=$MESA_V"                # the same Mesa source package
  "libdrm2=2.4.123-1~bpo12+1"
  "libdrm-amdgpu1=2.4.123-1~bpo12+1"
  "libdrm-common=2.4.123-1~bpo12+1"
)
RUST_TOOLCHAIN=1.95.0   # only used when cargo is missing; naga 30 needs rust >= 1.87
BPO_SOURCES=/etc/apt/sources.list.d/shadermatrix-bookworm-backports.sources

missing_of() {  # the specs of "$@" whose package is not installed at exactly that version
  local spec pkg want have
  for spec in "$@"; do
    pkg=${spec%%=*}; want=${spec#*=}
    have=$(dpkg-query -W -f='${Status} ${Version}' "$pkg" 2>/dev/null || true)
    [[ "$have" == "install ok installed $want" ]] || echo "$spec"
  done
}
mapfile -t missing < <(missing_of "${APT_PKGS[@]}")
mapfile -t missing_bpo < <(missing_of "${BPO_PKGS[@]}")
if ((${#missing_bpo[@]})) && ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  echo "setup: adding bookworm-backports to apt's sources ($BPO_SOURCES)"
  printf '%s\n' "Types: deb" "URIs: http://deb.debian.org/debian" "Suites: bookworm-backports" \
    "Components: main" "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg" > "$BPO_SOURCES.tmp"
  mv "$BPO_SOURCES.tmp" "$BPO_SOURCES"
fi
if ((${#missing[@]} + ${#missing_bpo[@]})); then
  echo "setup: installing ${missing[*]} ${missing_bpo[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  ((${#missing[@]} == 0)) || apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  if ((${#missing_bpo[@]})) &&
     ! apt-get install -y -qq --no-install-recommends --allow-downgrades -t bookworm-backports \
       "${missing_bpo[@]}" >/dev/null; then
    echo "setup: could not install ${missing_bpo[*]} from bookworm-backports — if a newer upload replaced" \
         "them, bump BPO_PKGS in scripts/setup.sh to what \`apt-cache policy mesa-vulkan-drivers\` lists" >&2
    exit 1
  fi
fi
# libc's headers (gcc only recommends them, and they follow libc6's own version): the C engine, pack.h's tests
# and naga's build scripts below include them
[[ -e /usr/include/stdio.h ]] || {
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq && apt-get install -y -qq --no-install-recommends libc6-dev >/dev/null
}

# naga (WGSL front end + validator), pinned, from crates.io into .tools/bin, which the end of this
# script links into .venv/bin. A naga of the pinned version already on PATH is used as is.
naga_version() { "$1" --version 2>/dev/null || true; }
if [[ "$(naga_version .tools/bin/naga)" != "$NAGA_VERSION" ]] &&
   ! { command -v naga >/dev/null 2>&1 && [[ "$(naga_version naga)" == "$NAGA_VERSION" ]]; }; then
  export PATH="${CARGO_HOME:-$HOME/.cargo}/bin:$PATH"
  if ! command -v cargo >/dev/null 2>&1; then
    # Debian's cargo (1.65) is too old for naga 30 (rust-version 1.87): pinned rustup toolchain.
    echo "setup: installing Rust $RUST_TOOLCHAIN (minimal profile) with rustup"
    command -v curl >/dev/null 2>&1 || {
      export DEBIAN_FRONTEND=noninteractive
      apt-get update -qq && apt-get install -y -qq --no-install-recommends curl ca-certificates >/dev/null
    }
    command -v cc >/dev/null 2>&1 || {
      export DEBIAN_FRONTEND=noninteractive
      apt-get update -qq && apt-get install -y -qq --no-install-recommends gcc libc6-dev >/dev/null
    }
    rustup_init=$(mktemp)
    curl --proto '=https' --tlsv1.2 -sSf -o "$rustup_init" \
      "https://static.rust-lang.org/rustup/dist/$(uname -m)-unknown-linux-gnu/rustup-init"
    chmod +x "$rustup_init"
    "$rustup_init" -y -q --profile minimal --default-toolchain "$RUST_TOOLCHAIN" --no-modify-path
    rm -f "$rustup_init"
  fi
  echo "setup: cargo install naga-cli $NAGA_VERSION into .tools (about a minute)"
  cargo install naga-cli --locked --version "$NAGA_VERSION" --root "$PWD/.tools" -q
fi

# Python environment in .venv with the package installed editable.
PY=${PYTHON:-python3}
if [[ ! -x .venv/bin/python ]]; then
  if ! "$PY" -c 'import ensurepip, venv' >/dev/null 2>&1; then  # Debian splits venv out
    echo "setup: installing python3-venv"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq && apt-get install -y -qq --no-install-recommends python3-venv >/dev/null
  fi
  "$PY" -m venv .venv
fi
stamp=.venv/.setup-stamp
want_stamp=$(cat requirements.lock pyproject.toml | sha256sum | cut -d' ' -f1)
if [[ ! -f $stamp || "$(cat $stamp)" != "$want_stamp" ]]; then
  echo "setup: installing Python packages into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check -r requirements.lock
  .venv/bin/python -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation --config-settings editable_mode=compat -e .
  echo "$want_stamp" > "$stamp"
fi

# A second Python, when this machine has one of another version: `make test` runs the loader, fuzz and
# interrupt tests on it too (Debian 12's own 3.11.2 and a newer 3.11 on PATH differ there: ast.parse of a NUL
# byte, a worker pool's shutdown). In a bare Debian 12 root there is one Python and no second environment.
py_version() { "$1" -c 'import sys; print(sys.version.split()[0])' 2>/dev/null || true; }
main_version=$(py_version .venv/bin/python)
alt=""
for cand in /usr/bin/python3 "$(command -v python3 || true)" "$(command -v python3.11 || true)" "$(command -v python3.12 || true)"; do
  [[ -n "$cand" && -x "$cand" ]] || continue
  v=$(py_version "$cand")
  [[ -n "$v" && "$v" != "$main_version" ]] && "$cand" -c 'import sys; sys.exit(sys.version_info < (3, 11, 2))' &&
    "$cand" -c 'import ensurepip, venv' >/dev/null 2>&1 && { alt=$cand; break; }
done
if [[ -n "$alt" ]]; then
  if [[ "$(py_version .venv-alt/bin/python)" != "$(py_version "$alt")" ]]; then
    rm -rf .venv-alt
    "$alt" -m venv .venv-alt
  fi
  if [[ ! -f .venv-alt/.setup-stamp || "$(cat .venv-alt/.setup-stamp)" != "$want_stamp" ]]; then
    echo "setup: installing Python packages into .venv-alt (Python $(py_version "$alt"), the second Python of make test)"
    if .venv-alt/bin/python -m pip install -q --disable-pip-version-check -r requirements.lock &&
       .venv-alt/bin/python -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation --config-settings editable_mode=compat -e .; then
      echo "$want_stamp" > .venv-alt/.setup-stamp
    else  # the second Python is a check beside the first, never a reason the set-up fails
      echo "setup: warning: could not install the packages for $alt — make test runs on .venv's Python only" >&2
      rm -rf .venv-alt
    fi
  fi
fi

# The naga built into .tools/bin, linked into the venv's bin/: shadermatrix looks for its tools in
# $SHADERMATRIX_TOOLS, then in the bin/ of the Python that runs it (so also when .venv is not activated),
# then on PATH (generator/toolchain/locate.py).
for venv in .venv .venv-alt; do
  [[ -d $venv/bin ]] || continue
  if [[ "$(naga_version .tools/bin/naga)" == "$NAGA_VERSION" ]]; then
    ln -sfn ../../.tools/bin/naga "$venv/bin/naga"
  elif [[ -L $venv/bin/naga ]]; then  # a link to a naga of another pin: the one on PATH is the pinned one
    rm -f "$venv/bin/naga"
  fi
done
