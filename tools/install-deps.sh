#!/bin/sh
# install-deps.sh - installs, from Debian's packages, what the tests need and
# this machine lacks: cmocka (unit tests), pkg-config and g++ (install and
# C++ header tests), python3 and python3-venv (binding tests: their venv,
# and a pip install of the binding into a fresh one), valgrind, the Cortex-M
# cross compiler with newlib (make cross) and qemu-system-arm (make target:
# the embedded examples on an emulated Cortex-M4F). Installs only what is
# missing; without root it prints the apt-get line instead and fails.
set -eu
missing=""
need() { # need PACKAGE TEST...
    pkg=$1; shift
    if ! "$@" >/dev/null 2>&1; then missing="$missing $pkg"; fi
}
need libcmocka-dev sh -c 'echo "#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
int main(void){return 0;}" | cc -x c - -o /dev/null -lcmocka'
need pkg-config command -v pkg-config
need g++ command -v g++
need python3 command -v python3
need python3-venv sh -c 'd=$(mktemp -d) && python3 -m venv "$d/v"; r=$?; rm -rf "$d"; exit $r'
need valgrind command -v valgrind
need gcc-arm-none-eabi command -v arm-none-eabi-gcc
need qemu-system-arm command -v qemu-system-arm
need libnewlib-arm-none-eabi sh -c 'echo "int main(void){return 0;}" | arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -specs=nosys.specs -x c - -o /dev/null'
[ -z "$missing" ] && { echo "install-deps: nothing missing"; exit 0; }
if [ "$(id -u)" != 0 ]; then
    echo "install-deps: missing:$missing; run: sudo apt-get install -y$missing" >&2
    exit 1
fi
echo "install-deps: installing:$missing"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# shellcheck disable=SC2086
apt-get install -y -qq $missing >/dev/null
