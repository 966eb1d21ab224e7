#!/usr/bin/env bash
# Builds the C example for QEMU mps2-an386 (Cortex-M4F) or, with
# EHA_CPU=cortex-m3, for mps2-an385 (Cortex-M3, no FPU: soft-float):
#   build.sh OUT_ELF [LIBEHA_GUARD_CAPI_A]
# The library defaults to the workspace's release build for
# thumbv7em-none-eabihf (cargo build --release -p eha-guard-capi
# --target thumbv7em-none-eabihf), or thumbv7m-none-eabi for the M3. Needs arm-none-eabi-gcc (Debian:
# gcc-arm-none-eabi). No C library: the static library brings the memory
# routines (compiler_builtins), libgcc the rest.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../../../.." && pwd)"
out="${1:?usage: build.sh OUT_ELF [LIB]}"
case "${EHA_CPU:-cortex-m4}" in
  cortex-m4) triple=thumbv7em-none-eabihf; cpu=(-mcpu=cortex-m4 -mfloat-abi=hard -mfpu=fpv4-sp-d16) ;;
  cortex-m3) triple=thumbv7m-none-eabi; cpu=(-mcpu=cortex-m3 -mfloat-abi=soft) ;;
  *) echo "EHA_CPU must be cortex-m4 or cortex-m3" >&2; exit 2 ;;
esac
lib="${2:-${CARGO_TARGET_DIR:-$root/target}/$triple/release/libeha_guard_capi.a}"
arm-none-eabi-gcc "${cpu[@]}" -mthumb \
  -std=c11 -O2 -g -Wall -Wextra -Werror -ffreestanding -ffunction-sections -fdata-sections \
  -I "$here/../../include" \
  -nostdlib -T "$here/link.ld" -Wl,--gc-sections -Wl,--no-warn-execstack -Wl,-Map="$out.map" \
  "$here/startup.c" "$here/semihost.c" "$here/main.c" "$lib" -lgcc -o "$out"
